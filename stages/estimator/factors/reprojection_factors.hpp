#pragma once
// Reprojection factors of an inverse-depth feature (VINS-Fusion's projection factors; VINS-Mono, Qin et
// al., T-RO 2018, §VI-C), over the blocks of parameter_layout.hpp. The feature is anchored in
// frame i's cam0: P_ci = (x_i, y_i, 1) / λ with (x_i, y_i) its anchor observation on the z = 1 plane.
// Extrinsics are pose blocks T_bc (cam → body), body poses are T_wb. The residual, on the z = 1 plane, is
//   r = w · s · (P_c.xy / P_c.z − xy_obs),
// with s = sqrt_info (focal length [px] / σ [px]) and w = *weight (DynaVINS' per-feature weight w_j,
// paper III; read at Evaluate time so the estimator can change it between solves; nullptr means 1).
// Jacobians of pose and extrinsic blocks fill the 6 tangent columns [δp, δθ] (right perturbation) and
// leave column 7 zero; a null entry in `jacobians` (constant block) is skipped.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

namespace dynavins::estimator {

/// Anchor in cam0 of frame i, observation in cam0 of frame j. Blocks: pose_i, pose_j, T_bc0, inv_depth.
class ProjectionTwoFrameOneCamFactor final : public ceres::SizedCostFunction<2, 7, 7, 7, 1> {
 public:
  /// `weight`, if not null, must outlive the factor.
  ProjectionTwoFrameOneCamFactor(const Eigen::Vector2d& xy_i, const Eigen::Vector2d& xy_j, double sqrt_info,
                                 const double* weight = nullptr);
  /// Weighted residual and the row-major Jacobian of each block whose entry in `jacobians` is not null.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector2d xy_i_, xy_j_;
  double sqrt_info_;
  const double* weight_;
};

/// Anchor in cam0 of frame i, observation in cam1 of frame j. Blocks: pose_i, pose_j, T_bc0, T_bc1,
/// inv_depth.
class ProjectionTwoFrameTwoCamFactor final : public ceres::SizedCostFunction<2, 7, 7, 7, 7, 1> {
 public:
  /// `weight`, if not null, must outlive the factor.
  ProjectionTwoFrameTwoCamFactor(const Eigen::Vector2d& xy_i, const Eigen::Vector2d& xy_j, double sqrt_info,
                                 const double* weight = nullptr);
  /// Weighted residual and the row-major Jacobian of each block whose entry in `jacobians` is not null.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector2d xy_i_, xy_j_;
  double sqrt_info_;
  const double* weight_;
};

/// Anchor in cam0, observation in cam1 of the same frame (the stereo residual). Blocks: T_bc0, T_bc1,
/// inv_depth.
class ProjectionOneFrameTwoCamFactor final : public ceres::SizedCostFunction<2, 7, 7, 1> {
 public:
  /// `weight`, if not null, must outlive the factor.
  ProjectionOneFrameTwoCamFactor(const Eigen::Vector2d& xy_i, const Eigen::Vector2d& xy_j, double sqrt_info,
                                 const double* weight = nullptr);
  /// Weighted residual and the row-major Jacobian of each block whose entry in `jacobians` is not null.
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  Eigen::Vector2d xy_i_, xy_j_;
  double sqrt_info_;
  const double* weight_;
};

}  // namespace dynavins::estimator
