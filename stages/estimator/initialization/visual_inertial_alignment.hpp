#pragma once
// Visual-inertial alignment (VINS-Mono T-RO 2018 §V-B-2 "Velocity, gravity vector and metric scale
// initialization", and §V-B-3 "Gravity refinement"). Reference frame c0 = the
// frame of the up-to-scale SfM. Unknowns: body-frame velocities v^bk of all frames, the gravity
// acceleration g^c0 (points down, |g| ≈ 9.81) and the metric scale s:
//   α_{k,k+1} - p_bc + R^bk_c0 R^c0_bk+1 p_bc = s R^bk_c0 (p̄_ck+1 - p̄_ck) - Δt v^bk - ½ Δt² R^bk_c0 g^c0
//   β_{k,k+1}                                 = R^bk_c0 R^c0_bk+1 v^bk+1 - v^bk - Δt R^bk_c0 g^c0
// (signs differ from the paper's because g here is the gravity acceleration, not its negative).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

/// Settings of align_visual_inertial().
struct VisualInertialAlignmentOptions {
  double gravity_norm = 9.81;            ///< known |g| [m/s^2]
  double max_gravity_norm_error = 1.0;   ///< the free-gravity solution must have ||g| - gravity_norm| below this
  int refinement_iterations = 4;         ///< tangent-sphere gravity refinements (VINS: 4)
  /// The refined scale's standard deviation (from the least-squares residual and the normal matrix)
  /// relative to the scale must stay below this: above it the window's motion did not excite the
  /// accelerometer enough to tell the scale (constant velocity, or a constant acceleration that the free
  /// gravity absorbs) and the noise picks it. Not in VINS (which accepts any s > 0). Loose on purpose:
  /// the window solve refines a rough scale; on the simulated street (0.5 s windows) good windows read
  /// 0.18-0.27 and degenerate ones 0.4-75. <= 0: no check.
  double max_scale_relative_std = 0.3;
  /// The window's accelerometer excitation (accelerometer_excitation()) must reach this [m/s^2]. The free
  /// gravity absorbs any constant acceleration, so only the acceleration's variation across the window
  /// carries the scale; when that variation is as small as the accelerometer's own error (bias drift,
  /// noise: a few 0.01 m/s^2), the scale is noise, however well it fits (the scale-std test above does
  /// not see it, since the visual track and the IMU then agree for any scale). Not in VINS-Mono, which
  /// only logs its excitation check. <= 0: no check.
  double min_excitation = 0.1;
};

/// Result of align_visual_inertial().
struct VisualInertialAlignment {
  bool success = false;
  std::string reason;                          ///< why it failed (empty on success)
  double scale = 0.0;                          ///< metric scale s: metric position = s * SfM position
  Eigen::Vector3d g_c0 = Eigen::Vector3d::Zero();   ///< gravity acceleration in c0, |g| = gravity_norm
  double free_gravity_norm = 0.0;              ///< |g| of the unconstrained solution (before refinement)
  double scale_relative_std = 0.0;             ///< std(s) / s of the refined solution
  double excitation = 0.0;                     ///< accelerometer_excitation() of the window [m/s^2]
  std::vector<Eigen::Vector3d> v_b;            ///< velocity of frame k expressed in body frame k [m/s]
};

/// Solves the alignment. R_c0_b[k]: body orientation of frame k in c0; p_c0_c[k]: camera position of
/// frame k in c0 up to scale (SfM); preints[k]: frame k -> k+1 (bias-corrected, repropagated);
/// p_bc: camera position in the body frame (extrinsic). Throws std::invalid_argument on mismatched sizes.
VisualInertialAlignment align_visual_inertial(const std::vector<Eigen::Matrix3d>& R_c0_b,
                                            const std::vector<Eigen::Vector3d>& p_c0_c,
                                            const std::vector<const imu::ImuPreintegration*>& preints,
                                            const Eigen::Vector3d& p_bc,
                                            const VisualInertialAlignmentOptions& options = {});

/// RMS deviation, over the window's intervals, of each interval's mean specific force expressed in c0
/// (R_c0_b[k] β_k / Δt_k) from their average [m/s^2]: how much the acceleration varies across the window.
double accelerometer_excitation(const std::vector<Eigen::Matrix3d>& R_c0_b,
                               const std::vector<const imu::ImuPreintegration*>& preints);

/// Two unit vectors spanning the plane orthogonal to g (VINS-Mono's TangentBasis).
Eigen::Matrix<double, 3, 2> gravity_tangent_basis(const Eigen::Vector3d& g);

}  // namespace dynavins::estimator
