#pragma once
// Rotation of cam0 between two frames from the gyro alone, to seed the tracker's KLT
// (StereoTracker::process's R_prev_curr_cam0). A pure rotation moves every pixel the same way
// whatever its depth, so the gyro predicts most of the image motion of a turning camera.
//
// The prediction is only made when the samples really cover the interval: the first sample at or
// before the previous frame, the last at or after the current one, no spacing above the gap limit.
// Anything else (first frame, a dropped frame in between, an IMU outage) gives no prediction rather
// than a guess: the tracker then simply runs its unseeded KLT.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "messages/sensor_messages.hpp"

namespace dynavins::tracker {

class GyroRotationPredictor {
 public:
  /// `body_T_cam0`: cam0 -> body (IMU) frame, as in the config's body_T_cam0 (only its rotation is used).
  /// `max_gap_ns`: a spacing of consecutive samples above it is an outage (no prediction). Must be > 0.
  GyroRotationPredictor(const Eigen::Isometry3d& body_T_cam0, int64_t max_gap_ns);

  /// Rotation of the cam0 frame at `t1_ns` expressed in the cam0 frame at `t0_ns` (p_prev = R * p_curr),
  /// from the gyro samples `imu` (time order; samples not after their predecessor are skipped) minus
  /// `bias_gyr`. std::nullopt unless t0 < t1 and the samples cover [t0, t1] without a gap.
  std::optional<Eigen::Matrix3d> predict(const std::vector<ImuSample>& imu, int64_t t0_ns, int64_t t1_ns,
                                         const Eigen::Vector3d& bias_gyr = Eigen::Vector3d::Zero()) const;

  /// The same in the body (IMU) frame: R_{b(t0) b(t1)}.
  std::optional<Eigen::Matrix3d> predict_body(const std::vector<ImuSample>& imu, int64_t t0_ns, int64_t t1_ns,
                                             const Eigen::Vector3d& bias_gyr = Eigen::Vector3d::Zero()) const;

  int64_t max_gap_ns() const { return max_gap_ns_; }

 private:
  Eigen::Matrix3d R_bc_;  // cam0 -> body rotation
  int64_t max_gap_ns_;
};

}  // namespace dynavins::tracker
