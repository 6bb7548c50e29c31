#include "stages/estimator/factors/acc_bias_prior_factor.hpp"

#include <stdexcept>

#include <Eigen/Core>

namespace dynavins::estimator {

AccBiasPriorFactor::AccBiasPriorFactor(double sigma) : inv_sigma_(1.0 / sigma) {
  if (!(sigma > 0)) throw std::invalid_argument("AccBiasPriorFactor: sigma must be positive");
}

bool AccBiasPriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> b_a(parameters[0] + 3);  // after the velocity
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = inv_sigma_ * b_a;
  if (jacobians && jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 3, 9, Eigen::RowMajor>> J(jacobians[0]);
    J.setZero();
    J.middleCols<3>(3).diagonal().setConstant(inv_sigma_);  // velocity and gyroscope bias: no effect
  }
  return true;
}

}  // namespace dynavins::estimator
