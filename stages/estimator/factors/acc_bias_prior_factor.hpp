#pragma once
// Prior on the accelerometer bias of one speed-bias block [9] of parameter_layout.hpp: r = b_a / σ (3),
// zero mean. Ours (issue 23), off by default (key acc_bias_prior_sigma): at rest gravity and the
// accelerometer bias are one measurement, and on a straight drive a tilt of the whole window changes no
// reprojection while the bias explains the tilted gravity, so nothing but a turn tells them apart. A
// VINS-Fusion window leaves that direction free; a filter (OpenVINS) starts from a bias covariance. This
// is that covariance: put on the first window's oldest slot and carried on by the marginalisation.

#include <ceres/sized_cost_function.h>

namespace dynavins::estimator {

class AccBiasPriorFactor final : public ceres::SizedCostFunction<3, 9> {
 public:
  /// `sigma` [m/s²]: the turn-on accelerometer bias expected per axis (> 0).
  explicit AccBiasPriorFactor(double sigma);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  double inv_sigma_;
};

}  // namespace dynavins::estimator
