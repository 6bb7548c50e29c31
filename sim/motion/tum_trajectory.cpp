#include "sim/motion/tum_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "eval/trajectory_io.hpp"

namespace dynavins::sim {

std::vector<TimedPose> read_tum_trajectory(const std::string& path) {
  // One TUM reader in the project (eval/): plain or gzip, every bad row named by file and line.
  const eval::Trajectory traj = eval::read_trajectory(path, eval::TrajectoryFormat::Tum);
  if (traj.empty()) throw std::runtime_error(path + ": no poses in trajectory file");
  std::vector<TimedPose> out;
  out.reserve(traj.size());
  for (const auto& pose : traj.poses) out.push_back({pose.t, pose.p, pose.q});
  return out;
}

std::vector<TimedPose> select_window(const std::vector<TimedPose>& poses, double window_start, double window_duration) {
  if (poses.empty()) throw std::invalid_argument("select_window: empty pose list");
  const double a = poses.front().t + window_start;
  const double b = window_duration > 0.0 ? a + window_duration : poses.back().t;
  std::vector<TimedPose> out;
  for (const TimedPose& s : poses)
    if (s.t >= a && s.t <= b) out.push_back(s);
  if (out.size() < 2)
    throw std::invalid_argument("select_window: window [" + std::to_string(window_start) + " s, +" +
                                std::to_string(window_duration) + " s] holds fewer than 2 poses");
  return out;
}

int remove_position_jumps(std::vector<TimedPose>& poses, double glitch_acceleration, double min_jump) {
  if (glitch_acceleration <= 0.0 || poses.size() < 4) return 0;
  const int n = static_cast<int>(poses.size());
  auto stepVelocity = [&](int j) { return Eigen::Vector3d((poses[j].p - poses[j - 1].p) / (poses[j].t - poses[j - 1].t)); };
  // Only regular steps are judged: across a dropout (TUM-VI has gaps of up to 1 s) a large step is motion.
  std::vector<double> steps;
  for (int j = 1; j < n; ++j) steps.push_back(poses[j].t - poses[j - 1].t);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double regular_dt = 1.5 * steps[steps.size() / 2];
  int removed = 0;
  for (int m = 1; m < n; ++m) {
    const double dt = poses[m].t - poses[m - 1].t;
    if (dt > regular_dt) continue;
    const double threshold = std::max(min_jump, 3.0 * glitch_acceleration * dt * dt);
    std::vector<Eigen::Vector3d> nb;
    for (int j = m - 3; j <= m + 3; ++j)
      if (j != m && j >= 1 && j < n) nb.push_back(stepVelocity(j));
    if (nb.size() < 2) continue;
    Eigen::Vector3d med;
    for (int ax = 0; ax < 3; ++ax) {
      std::vector<double> c;
      for (const auto& v : nb) c.push_back(v[ax]);
      std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
      double hi = c[c.size() / 2];
      if (c.size() % 2 == 0) hi = 0.5 * (hi + *std::max_element(c.begin(), c.begin() + c.size() / 2));
      med[ax] = hi;
    }
    const Eigen::Vector3d excess = (poses[m].p - poses[m - 1].p) - med * (poses[m].t - poses[m - 1].t);
    if (excess.norm() > threshold) {
      for (int j = m; j < n; ++j) poses[j].p -= excess;
      ++removed;
    }
  }
  return removed;
}

SmoothTrajectory fit_tum_trajectory(const std::string& path, const TumFitOptions& o, TumFitReport* report) {
  std::vector<TimedPose> poses = select_window(read_tum_trajectory(path), o.window_start, o.window_duration);
  const int removed = remove_position_jumps(poses, o.glitch_acceleration);
  if (removed > 0) spdlog::info("{}: removed {} position glitch(es) before fitting", path, removed);
  const double offset = o.shift_to_zero ? poses.front().t : 0.0;
  const Eigen::Quaterniond q_world(o.world_from_file.linear()), q_body(o.file_body_from_body);
  for (TimedPose& s : poses) {
    s.t -= offset;
    s.p = o.world_from_file * s.p;
    s.q = (q_world * s.q * q_body).normalized();
  }
  TrajectoryFitReport fr;
  SmoothTrajectory traj = fit_trajectory(poses, o.fit, &fr);
  if (report) {
    report->fit = fr;
    report->time_offset = offset;
    report->removed_jumps = removed;
  }
  return traj;
}

}  // namespace dynavins::sim
