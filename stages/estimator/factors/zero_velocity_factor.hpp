#pragma once
// Zero-velocity factor (ZUPT) on one speed-bias block [9] of parameter_layout.hpp: r = v_wb / σ_v (3).
// Added for frames the StandstillDetector finds at rest, so that a still camera whose view holds no
// triangulated static point (a mono camera after a truck hid everything it had a depth for) does not
// drift on the IMU alone. Not in the paper; OpenVINS' zero-velocity update plays the same role.

#include <ceres/sized_cost_function.h>

namespace dynavins::estimator {

class ZeroVelocityFactor final : public ceres::SizedCostFunction<3, 9> {
 public:
  /// `sigma` [m/s]: how far from zero the velocity of a frame at rest may be (> 0).
  explicit ZeroVelocityFactor(double sigma);

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  double inv_sigma_;
};

}  // namespace dynavins::estimator
