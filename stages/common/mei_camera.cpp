#include "stages/common/mei_camera.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace dynavins {

MeiCamera::MeiCamera(const Params& params) : p_(params) {
  if (p_.gamma1 <= 0 || p_.gamma2 <= 0) throw std::invalid_argument("MEI: gamma1 and gamma2 must be positive");
  if (p_.xi < 0) throw std::invalid_argument("MEI: xi must be non-negative");
  if (p_.width <= 0 || p_.height <= 0) throw std::invalid_argument("MEI: image size must be positive");
}

Eigen::Vector3d MeiCamera::lift(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - p_.u0) / p_.gamma1, (pixel.y() - p_.v0) / p_.gamma2);
  const Eigen::Vector2d m = p_.distortion.undistort(d);
  // Inverse of the unified model: the sphere point whose shifted projection is m.
  const double r2 = m.squaredNorm();
  const double disc = 1.0 + (1.0 - p_.xi * p_.xi) * r2;
  if (disc < 0) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const double s = (p_.xi + std::sqrt(disc)) / (1.0 + r2);
  return Eigen::Vector3d(s * m.x(), s * m.y(), s - p_.xi).normalized();
}

Eigen::Vector2d MeiCamera::project(const Eigen::Vector3d& P, Jacobian* jacobian) const {
  const double n = P.norm();
  const double den = P.z() + p_.xi * n;
  const Eigen::Vector2d m(P.x() / den, P.y() / den);
  Eigen::Matrix2d Jd;
  const Eigen::Vector2d d = p_.distortion.distort(m, jacobian ? &Jd : nullptr);
  if (jacobian) {
    // m = (X, Y) / den with den = Z + xi*|P|; d(den)/dP = (xi X/n, xi Y/n, 1 + xi Z/n).
    const Eigen::RowVector3d dden(p_.xi * P.x() / n, p_.xi * P.y() / n, 1.0 + p_.xi * P.z() / n);
    Eigen::Matrix<double, 2, 3> Jm;
    Jm.row(0) = -P.x() / (den * den) * dden;
    Jm.row(1) = -P.y() / (den * den) * dden;
    Jm(0, 0) += 1.0 / den;
    Jm(1, 1) += 1.0 / den;
    const Eigen::Matrix2d K = Eigen::Vector2d(p_.gamma1, p_.gamma2).asDiagonal();
    *jacobian = K * Jd * Jm;
  }
  return {p_.gamma1 * d.x() + p_.u0, p_.gamma2 * d.y() + p_.v0};
}

std::string MeiCamera::describe() const {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "MEI %dx%d xi=%.6g gamma1=%.6g gamma2=%.6g u0=%.6g v0=%.6g k1=%.6g k2=%.6g p1=%.6g p2=%.6g",
                p_.width, p_.height, p_.xi, p_.gamma1, p_.gamma2, p_.u0, p_.v0, p_.distortion.k1,
                p_.distortion.k2, p_.distortion.p1, p_.distortion.p2);
  return buf;
}

}  // namespace dynavins
