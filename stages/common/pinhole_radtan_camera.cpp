#include "stages/common/pinhole_radtan_camera.hpp"

#include <cstdio>
#include <stdexcept>

namespace dynavins {

PinholeRadtanCamera::PinholeRadtanCamera(const Params& params) : p_(params) {
  if (p_.fx <= 0 || p_.fy <= 0) throw std::invalid_argument("PINHOLE: fx and fy must be positive");
  if (p_.width <= 0 || p_.height <= 0) throw std::invalid_argument("PINHOLE: image size must be positive");
}

Eigen::Vector3d PinholeRadtanCamera::lift(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - p_.cx) / p_.fx, (pixel.y() - p_.cy) / p_.fy);
  const Eigen::Vector2d m = p_.distortion.undistort(d);
  return Eigen::Vector3d(m.x(), m.y(), 1.0).normalized();
}

Eigen::Vector2d PinholeRadtanCamera::project(const Eigen::Vector3d& P, Jacobian* jacobian) const {
  const double iz = 1.0 / P.z();
  const Eigen::Vector2d m(P.x() * iz, P.y() * iz);
  Eigen::Matrix2d Jd;
  const Eigen::Vector2d d = p_.distortion.distort(m, jacobian ? &Jd : nullptr);
  if (jacobian) {
    Eigen::Matrix<double, 2, 3> Jm;  // d(m)/d(P)
    Jm << iz, 0, -P.x() * iz * iz, 0, iz, -P.y() * iz * iz;
    const Eigen::Matrix2d K = Eigen::Vector2d(p_.fx, p_.fy).asDiagonal();
    *jacobian = K * Jd * Jm;
  }
  return {p_.fx * d.x() + p_.cx, p_.fy * d.y() + p_.cy};
}

std::string PinholeRadtanCamera::describe() const {
  char buf[256];
  std::snprintf(buf, sizeof buf, "PINHOLE %dx%d fx=%.6g fy=%.6g cx=%.6g cy=%.6g k1=%.6g k2=%.6g p1=%.6g p2=%.6g",
                p_.width, p_.height, p_.fx, p_.fy, p_.cx, p_.cy, p_.distortion.k1, p_.distortion.k2,
                p_.distortion.p1, p_.distortion.p2);
  return buf;
}

}  // namespace dynavins
