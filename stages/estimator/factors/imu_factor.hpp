#pragma once
// The IMU factor between two consecutive window states (VINS-Mono, Qin et al., T-RO 2018, §VI-B: residual,
// and the Jacobians of its IMUFactor), over the blocks of parameter_layout.hpp:
//   pose_i [7], speed-bias_i [9], pose_j [7], speed-bias_j [9].
// Residual r = S e, e = ImuPreintegration::evaluate_residual() (15), S the upper Cholesky factor of the
// information P^-1, so ||r||² = e^T P^-1 e (Mahalanobis). Pose Jacobians fill the 6 tangent columns
// [δp, δθ] (right perturbation) and leave column 7 zero.

#include <mutex>

#include <ceres/sized_cost_function.h>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

class ImuFactor final : public ceres::SizedCostFunction<15, 7, 9, 7, 9> {
 public:
  /// `preintegration` is owned by the caller and must outlive the factor; it is read at every Evaluate
  /// (so it may be repropagated between solves). `gravity` is |g| [m/s²], world gravity (0, 0, -gravity).
  ImuFactor(const imu::ImuPreintegration* preintegration, double gravity);

  /// Whitened residual and (for each non-null entry of `jacobians`) its row-major Jacobian.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  /// Upper-triangular S with S^T S = covariance^-1 (VINS-Mono's sqrt_information).
  static Eigen::Matrix<double, 15, 15> sqrt_information(const imu::ImuPreintegration::Matrix15& covariance);

 private:
  /// sqrt_information(covariance), recomputed only when the preintegration's covariance changed.
  Eigen::Matrix<double, 15, 15> whitening(const imu::ImuPreintegration::Matrix15& covariance) const;

  const imu::ImuPreintegration* preintegration_;
  double gravity_;
  mutable std::mutex cache_mutex_;
  mutable bool cache_valid_ = false;
  mutable imu::ImuPreintegration::Matrix15 cached_covariance_;
  mutable Eigen::Matrix<double, 15, 15> cached_sqrt_information_;
};

}  // namespace dynavins::estimator
