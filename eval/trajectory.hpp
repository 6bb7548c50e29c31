#pragma once
// A stamped pose trajectory as read from TUM / EuRoC files: T_world_body per timestamp.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace dynavins::eval {

/// One pose T_world_body at a time stamp. Both time forms are kept: `t` (seconds, what evo
/// associates on) and `t_ns` (exact integer nanoseconds, used for ordering checks and output).
struct StampedPose {
  double t = 0.0;
  std::int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // unit norm
};

/// The pose at `t_ns` (both time forms filled, `q` normalised).
inline StampedPose stamped_pose(std::int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  StampedPose s;
  s.t_ns = t_ns;
  s.t = static_cast<double>(t_ns) * 1e-9;
  s.p = p;
  s.q = q.normalized();
  return s;
}

/// A trajectory with strictly increasing time stamps; `source` names its file for messages.
struct Trajectory {
  std::string source;
  std::vector<StampedPose> poses;

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
};

}  // namespace dynavins::eval
