#include "stages/estimator/pose_manifold.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "stages/common/so3.hpp"

namespace dynavins::estimator {

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  Eigen::Map<const Eigen::Vector3d> p(x), dp(delta), dtheta(delta + 3);
  Eigen::Map<const Eigen::Quaterniond> q(x + 3);
  Eigen::Map<Eigen::Vector3d> p_out(x_plus_delta);
  Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta + 3);
  p_out = p + dp;
  q_out = (q * Eigen::Quaterniond(so3::exp(dtheta))).normalized();
  return true;
}

bool PoseManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<const Eigen::Vector3d> py(y), px(x);
  Eigen::Map<const Eigen::Quaterniond> qy(y + 3), qx(x + 3);
  Eigen::Map<Eigen::Matrix<double, 6, 1>> d(y_minus_x);
  d.head<3>() = py - px;
  d.tail<3>() = so3::log((qx.conjugate() * qy).normalized().toRotationMatrix());
  return true;
}

bool PoseManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.leftCols<6>().setIdentity();
  return true;
}

}  // namespace dynavins::estimator
