#pragma once
// One preintegrated IMU interval between two consecutive frames, as emitted by ImuIntervalBuilder.
// Plain data (the lead may move it to messages/).

#include <cstdint>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins {

/// The IMU between frame i (t_begin_ns) and frame j (t_end_ns), both ends interpolated at the frame times.
struct PreintegratedInterval {
  int64_t t_begin_ns = 0;     ///< time of frame i
  int64_t t_end_ns = 0;       ///< time of frame j
  ImuPreintegration preint;   ///< deltas, covariance, bias Jacobian and the raw samples used
  bool has_gap = false;       ///< two consecutive IMU samples used here are further apart than the threshold
  int64_t max_gap_ns = 0;     ///< largest spacing of consecutive raw IMU samples bracketing/inside the interval
  int num_raw_samples = 0;    ///< real IMU samples inside (t_begin, t_end], interpolated ends not counted
};

}  // namespace dynavins
