#pragma once
// Applies the loop closer's keyframe corrections to a whole odometry trajectory (every frame, not only
// keyframes), as VINS-Fusion's pose graph does with its drift (r_drift, t_drift): a frame gets the
// correction of the nearest keyframe at or before it, T_W^corrected = T_corr * T_W^odom.

#include <cstdint>
#include <vector>

#include "stages/loop/graph/rigid_pose.hpp"

namespace dynavins::loop {

/// A timestamped body pose T_W^b.
struct StampedPose {
  int64_t t_ns = 0;
  RigidPose T_W_b;
};

/// The correction of one keyframe: T_corr = T_W^k_corrected * (T_W^k_odom)^-1 (a yaw rotation and a
/// translation after the 4-DoF pose graph).
struct KeyframeCorrection {
  int64_t t_ns = 0;
  RigidPose T_corr;
};

/// The drift correction that maps a keyframe's odometry pose onto its corrected pose.
RigidPose drift_correction(const RigidPose& T_W_k_odom, const RigidPose& T_W_k_corrected);

/// Corrects every pose of `odometry` (any order) with the correction of the latest keyframe whose t_ns is
/// <= the pose's t_ns. `corrections` must be sorted by t_ns (as LoopCloser::keyframe_corrections gives
/// them). Poses before the first keyframe, or all poses when `corrections` is empty, stay as they are
/// (the first keyframe is the pose graph's fixed gauge, its correction is the identity).
std::vector<StampedPose> correct_trajectory(const std::vector<StampedPose>& odometry,
                                            const std::vector<KeyframeCorrection>& corrections);

}  // namespace dynavins::loop
