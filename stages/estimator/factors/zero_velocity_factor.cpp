#include "stages/estimator/factors/zero_velocity_factor.hpp"

#include <stdexcept>

#include <Eigen/Core>

namespace dynavins::estimator {

ZeroVelocityFactor::ZeroVelocityFactor(double sigma) : inv_sigma_(1.0 / sigma) {
  if (!(sigma > 0)) throw std::invalid_argument("ZeroVelocityFactor: sigma must be positive");
}

bool ZeroVelocityFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> v(parameters[0]);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = inv_sigma_ * v;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 3, 9, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.leftCols<3>().diagonal().setConstant(inv_sigma_);  // biases: no effect
  }
  return true;
}

}  // namespace dynavins::estimator
