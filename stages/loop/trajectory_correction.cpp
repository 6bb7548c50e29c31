// Per-frame drift correction from the keyframe corrections (see trajectory_correction.hpp).
#include "stages/loop/trajectory_correction.hpp"

#include <algorithm>

namespace dynavins::loop {

RigidPose drift_correction(const RigidPose& T_W_k_odom, const RigidPose& T_W_k_corrected) {
  return compose(T_W_k_corrected, inverse(T_W_k_odom));
}

std::vector<StampedPose> correct_trajectory(const std::vector<StampedPose>& odometry,
                                            const std::vector<KeyframeCorrection>& corrections) {
  std::vector<StampedPose> out;
  out.reserve(odometry.size());
  for (const StampedPose& pose : odometry) {
    // First keyframe strictly after the frame; the one before it is the latest at or before the frame.
    const auto after = std::upper_bound(corrections.begin(), corrections.end(), pose.t_ns,
                                        [](int64_t t, const KeyframeCorrection& c) { return t < c.t_ns; });
    if (after == corrections.begin()) {
      out.push_back(pose);
      continue;
    }
    out.push_back(StampedPose{pose.t_ns, compose(std::prev(after)->T_corr, pose.T_W_b)});
  }
  return out;
}

}  // namespace dynavins::loop
