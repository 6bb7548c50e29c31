#pragma once
// Gauge of the sliding window: the oldest frame's position and yaw, which no measurement fixes (VIO
// observes neither a global translation nor a rotation about gravity). Only the marginalisation prior's
// small, linearisation-made information touches them, and left free a solve drifts them along it: on the
// sim street the estimated yaw wandered 2-8 deg (stereo `none` ATE 0.49 m). As VINS-Fusion does after
// every solve (Estimator::double2vector), the window is moved back so that its oldest frame keeps the
// position and yaw it had before the solve; roll and pitch (which gravity makes observable) stay solved.

#include <Eigen/Core>

#include "stages/estimator/window_state.hpp"

namespace dynavins::estimator {

class WindowGauge {
 public:
  /// Remembers slot 0's position and orientation (call before the solve).
  static WindowGauge of(const WindowState& s);

  /// Rotates slots 0..newest about world z (positions, orientations, velocities) and translates them so
  /// that slot 0 has the remembered position and yaw again. Near pitch ±90 deg, where yaw is undefined,
  /// the whole rotation of slot 0 is undone instead (as VINS-Fusion does). Feature inverse depths live
  /// in their anchor cameras and need no change.
  void restore(WindowState& s, int newest) const;

 private:
  Eigen::Vector3d p0_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R0_ = Eigen::Matrix3d::Identity();
};

}  // namespace dynavins::estimator
