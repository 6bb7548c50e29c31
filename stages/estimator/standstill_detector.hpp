#pragma once
// Is the camera at rest between the window's two newest frames? The test behind the zero-velocity
// factor (factors/zero_velocity_factor.hpp), after OpenVINS' zero-velocity disparity check:
//   - the median rotation-compensated displacement of the features seen in both frames is below
//     `max_disparity_px` (on the z = 1 plane, scaled by kNominalFocalPx like the keyframe parallax);
//   - at least `min_features` features enter that median;
//   - the last solve's speed is below `max_speed`, so a camera moving past a scene too far to show
//     parallax in one frame is not stopped by it.
// Features the robust BA rejected (weight below `min_weight`) are left out, so a truck crossing a still
// camera's view does not hide the standstill, and static points seen while the truck drives do not fake one
// for a moving camera unless they themselves stand still in the image. Not in the paper.

#include <Eigen/Core>

#include "stages/estimator/window_features.hpp"

namespace dynavins::estimator {

struct StandstillOptions {
  bool enabled = true;
  double max_disparity_px = 0.5;  ///< OpenVINS' zupt_max_disparity
  double max_speed = 0.1;         ///< m/s; OpenVINS' zupt_max_velocity
  int min_features = 20;
  double min_weight = 0.5;        ///< features below it (rejected by the robust BA) are not counted
};

struct StandstillCheck {
  bool still = false;
  int features = 0;                 ///< features in the median
  double median_disparity_px = -1;  ///< -1 when no feature was seen in both frames
};

/// Tests slot `newest` against slot `newest - 1`. `R_prev_new` rotates cam0 of the newest frame into cam0 of
/// the previous one (from the IMU-predicted states); `speed` is |v| of the previous frame [m/s].
StandstillCheck check_standstill(const WindowFeatures& features, int newest, const Eigen::Matrix3d& R_prev_new,
                                double speed, const StandstillOptions& options);

}  // namespace dynavins::estimator
