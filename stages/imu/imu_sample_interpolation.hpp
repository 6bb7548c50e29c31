#pragma once
// One IMU sample linearly interpolated between two: how the IMU stage (interval ends, propagation
// restarts) and the tracker's gyro prediction read the IMU at a time between samples.

#include <cstdint>

#include "messages/sensor_messages.hpp"

namespace dynavins::imu {

/// The measurements at t, a.t_ns <= t <= b.t_ns and a.t_ns < b.t_ns; exactly a or b at the ends.
inline ImuSample interpolate(const ImuSample& a, const ImuSample& b, int64_t t) {
  if (t == a.t_ns) return a;
  if (t == b.t_ns) return b;
  const double w = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  ImuSample s;
  s.t_ns = t;
  s.acc = (1.0 - w) * a.acc + w * b.acc;
  s.gyr = (1.0 - w) * a.gyr + w * b.gyr;
  return s;
}

}  // namespace dynavins::imu
