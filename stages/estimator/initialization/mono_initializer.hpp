#pragma once
// Monocular visual-inertial initialisation (VINS-Mono T-RO 2018 §V; VINS-Mono code: initialStructure +
// visualInitialAlign): vision-only SfM of the window -> gyroscope bias from the SfM rotations ->
// repropagation -> velocities, gravity and scale -> a gravity-aligned metric world.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/estimator/initialization/frame_features.hpp"
#include "stages/estimator/initialization/mono_sfm.hpp"
#include "stages/estimator/initialization/visual_inertial_alignment.hpp"
#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

/// One frame of the initialisation window.
struct InitWindowFrame {
  double t = 0.0;                         ///< frame time [s]
  FrameFeatures features;                 ///< cam0 normalized observations
  imu::ImuPreintegration* preint = nullptr;    ///< frame k-1 -> k; null for the first frame. Repropagated in place.
};

/// Settings of initialize_mono(). The gravity magnitude is alignment.gravity_norm.
struct MonoInitOptions {
  MonoSfmOptions sfm;
  VisualInertialAlignmentOptions alignment;
};

/// Depth of a feature in the cam0 frame of its anchor (first observing) frame.
struct FeatureDepth {
  int anchor_frame = 0;
  double depth = 0.0;  ///< z in the anchor camera [m]
};

/// Result of initialize_mono(). World: z up (g_w = (0, 0, -g)), yaw of frame 0 zero, origin at frame 0's body.
struct MonoInitResult {
  bool success = false;
  std::string reason;                      ///< why it failed (empty on success)
  bool sfm_succeeded = false;              ///< the SfM worked: a failure is the alignment's (scale, gravity)
  std::vector<Eigen::Matrix3d> R_wb;       ///< body-to-world rotation per frame
  std::vector<Eigen::Vector3d> p_wb;       ///< body position per frame [m]
  std::vector<Eigen::Vector3d> v_wb;       ///< body velocity in the world per frame [m/s]
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();  ///< gyroscope bias (the preintegrations' new linearisation bias)
  double scale = 0.0;                      ///< metric / SfM scale
  double scale_relative_std = 0.0;         ///< std(scale) / scale of the alignment
  std::map<FeatureId, FeatureDepth> depths;      ///< per feature id, for the SfM-triangulated features
  int sfm_reference_frame = -1;            ///< frame l of the SfM
  double sfm_rms_reprojection_px = 0.0;    ///< SfM bundle adjustment RMS error
};

/// Initialises from a window (index 0 = oldest). R_bc, p_bc: cam0-to-body extrinsic. Once the SfM has
/// succeeded the preintegrations are repropagated with the estimated gyroscope bias (and their own ba),
/// even if the alignment then fails (as VINS-Mono). Never throws on bad data: success == false + reason.
MonoInitResult initialize_mono(const std::vector<InitWindowFrame>& window, const Eigen::Matrix3d& R_bc,
                              const Eigen::Vector3d& p_bc, const MonoInitOptions& options = {});

}  // namespace dynavins::estimator
