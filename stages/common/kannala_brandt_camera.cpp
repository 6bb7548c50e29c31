#include "stages/common/kannala_brandt_camera.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace dynavins {

KannalaBrandtCamera::KannalaBrandtCamera(const Params& params) : p_(params) {
  if (p_.mu <= 0 || p_.mv <= 0) throw std::invalid_argument("KANNALA_BRANDT: mu and mv must be positive");
  if (p_.width <= 0 || p_.height <= 0) throw std::invalid_argument("KANNALA_BRANDT: image size must be positive");
}

double KannalaBrandtCamera::poly(double t, double* dpoly) const {
  const double t2 = t * t;
  if (dpoly) *dpoly = 1 + t2 * (3 * p_.k2 + t2 * (5 * p_.k3 + t2 * (7 * p_.k4 + t2 * 9 * p_.k5)));
  return t * (1 + t2 * (p_.k2 + t2 * (p_.k3 + t2 * (p_.k4 + t2 * p_.k5))));
}

Eigen::Vector3d KannalaBrandtCamera::lift(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - p_.u0) / p_.mu, (pixel.y() - p_.v0) / p_.mv);
  const double rd = d.norm();
  if (rd < 1e-12) return Eigen::Vector3d::UnitZ();
  // Newton on poly(theta) = rd; poly is monotone over any calibrated field of view.
  double t = rd;
  for (int i = 0; i < 30; ++i) {
    double dp;
    const double r = poly(t, &dp) - rd;
    if (std::abs(r) < 1e-14) break;
    t -= r / dp;
  }
  const double s = std::sin(t) / rd;
  return {s * d.x(), s * d.y(), std::cos(t)};
}

Eigen::Vector2d KannalaBrandtCamera::project(const Eigen::Vector3d& P, Jacobian* jacobian) const {
  const double r = std::hypot(P.x(), P.y());
  if (r < 1e-12 * std::abs(P.z())) {
    // On the optical axis the model is locally a pinhole with focal lengths mu mv.
    if (jacobian) *jacobian << p_.mu / P.z(), 0, 0, 0, p_.mv / P.z(), 0;
    return {p_.u0, p_.v0};
  }
  const double t = std::atan2(r, P.z());
  double dp;
  const double td = poly(t, jacobian ? &dp : nullptr);
  const Eigen::Vector2d dir(P.x() / r, P.y() / r);
  if (jacobian) {
    const double rho2 = r * r + P.z() * P.z();
    const Eigen::RowVector3d dt(P.z() * dir.x() / rho2, P.z() * dir.y() / rho2, -r / rho2);
    Eigen::Matrix<double, 2, 3> ddir;  // d(P.xy / r)/dP
    const double r3 = r * r * r;
    ddir << P.y() * P.y() / r3, -P.x() * P.y() / r3, 0, -P.x() * P.y() / r3, P.x() * P.x() / r3, 0;
    const Eigen::Matrix<double, 2, 3> Jn = dir * (dp * dt) + td * ddir;
    const Eigen::Matrix2d K = Eigen::Vector2d(p_.mu, p_.mv).asDiagonal();
    *jacobian = K * Jn;
  }
  return {p_.mu * td * dir.x() + p_.u0, p_.mv * td * dir.y() + p_.v0};
}

std::string KannalaBrandtCamera::describe() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "KANNALA_BRANDT %dx%d mu=%.6g mv=%.6g u0=%.6g v0=%.6g k2=%.6g k3=%.6g k4=%.6g k5=%.6g", p_.width,
                p_.height, p_.mu, p_.mv, p_.u0, p_.v0, p_.k2, p_.k3, p_.k4, p_.k5);
  return buf;
}

}  // namespace dynavins
