#pragma once
// The IMU tests' shared motion: 3D, ~1 rad/s rotation rates and ~1 m/s^2 accelerations on all axes,
// `duration` seconds long (waypoints every 0.5 s).
#include <cmath>
#include <vector>

#include "sim/motion/waypoint_path.hpp"

namespace dynavins::sim {

inline SmoothTrajectory wavy_trajectory(double duration = 8.0) {
  std::vector<Waypoint> w;
  for (int k = 0; 0.5 * k <= duration; ++k) {
    const double t = 0.5 * k;
    Waypoint p;
    p.t = t;
    p.p = Eigen::Vector3d(2.0 * std::sin(0.6 * t), 1.5 * std::cos(0.5 * t), 0.4 * std::sin(0.9 * t));
    p.yaw = 0.8 * std::sin(0.7 * t);
    p.pitch = 0.3 * std::sin(1.1 * t);
    p.roll = 0.25 * std::cos(0.9 * t);
    w.push_back(p);
  }
  return trajectory_from_timed_waypoints(w);
}

}  // namespace dynavins::sim
