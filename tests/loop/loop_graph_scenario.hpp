#pragma once
// Synthetic loop-closure scenario shared by the pose-graph tests: two laps of a 10 m square (keyframes
// every 0.5 m, 160 in all, lap 2 offset 0.3 m sideways), gentle z, roll and pitch; odometry integrates
// the true relative motion with yaw drift, scale error and z drift (roll and pitch exact, as the IMU
// keeps them). Loops go from lap-2 keyframes to lap-1 ones: true loops carry the true T_m^k; false loops
// are PnP against an object relocated by `shift` since C_m, so they put C_k at gt_k - shift.
// Deterministic: no random numbers.

#include <cmath>
#include <cstdint>
#include <vector>

#include "messages/keyframe.hpp"
#include "stages/loop/graph/keyframe_grouper.hpp"
#include "stages/loop/graph/rigid_pose.hpp"

namespace dynavins::loop::test {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct LoopScenario {
  static constexpr int kPerSide = 20;
  static constexpr int kPerLap = 4 * kPerSide;
  static constexpr int kNumKeyframes = 2 * kPerLap;

  std::vector<int64_t> t_ns;
  std::vector<RigidPose> gt, odom;
  std::vector<KeyframeGroup> groups;  // lap 2 in groups of 10 keyframes (lap 1 too: groups without loops)
  std::vector<VerifiedLoop> loops;
  std::vector<bool> loop_is_true;

  explicit LoopScenario(double yaw_drift_per_kf = 0.12 * kDeg, double scale = 1.03, double z_drift_per_kf = 0.003) {
    for (int k = 0; k < kNumKeyframes; ++k) {
      const int lap = k / kPerLap, along = k % kPerLap, side = along / kPerSide, step = along % kPerSide;
      const double s = 0.5 * step;
      const double off = lap == 0 ? 0.0 : 0.3;  // lap 2 runs 0.3 m inside the square
      double x = 0, y = 0;
      switch (side) {
        case 0:
          x = s, y = off;
          break;
        case 1:
          x = 10.0 - off, y = s;
          break;
        case 2:
          x = 10.0 - s, y = 10.0 - off;
          break;
        default:
          x = off, y = 10.0 - s;
          break;
      }
      const double yaw = side * 90.0 * kDeg;
      const double z = 0.2 * std::sin(0.15 * k);
      const double pitch = 2.0 * kDeg * std::sin(0.31 * k), roll = 1.5 * kDeg * std::cos(0.23 * k);
      gt.push_back(RigidPose{Eigen::Vector3d(x, y, z), quat_from_ypr(yaw, pitch, roll)});
      t_ns.push_back(1'000'000'000LL + 100'000'000LL * k);
    }
    // Odometry: true relative motion (in the yaw frame) with drift; starts at the true first pose.
    odom.push_back(gt[0]);
    double yaw_o = yaw_of(gt[0].q);
    for (int k = 1; k < kNumKeyframes; ++k) {
      const double yaw_prev_gt = yaw_of(gt[k - 1].q);
      const Eigen::Vector3d d_gt = Eigen::AngleAxisd(-yaw_prev_gt, Eigen::Vector3d::UnitZ()) * (gt[k].p - gt[k - 1].p);
      Eigen::Vector3d d = scale * d_gt;
      d.z() = d_gt.z() + z_drift_per_kf;
      const Eigen::Vector3d p = odom.back().p + Eigen::AngleAxisd(yaw_o, Eigen::Vector3d::UnitZ()) * d;
      yaw_o = normalize_angle(yaw_o + normalize_angle(yaw_of(gt[k].q) - yaw_prev_gt) + yaw_drift_per_kf);
      odom.push_back(RigidPose{p, quat_from_ypr(yaw_o, pitch_of(gt[k].q), roll_of(gt[k].q))});
    }
    for (int g = 0; g < kNumKeyframes / 10; ++g) {
      KeyframeGroup grp;
      for (int k = 10 * g; k < 10 * g + 10; ++k) grp.t_ns.push_back(t_ns[static_cast<std::size_t>(k)]);
      groups.push_back(grp);
    }
  }

  /// Group index (into groups) of lap-2 group j (0..7).
  static int lap2_group(int j) { return kPerLap / 10 + j; }

  void add_true_loop(int query, int match) {
    push(query, match, compose(inverse(gt[static_cast<std::size_t>(match)]), gt[static_cast<std::size_t>(query)]),
         true);
  }
  /// A loop against an object that moved by `shift` since it was seen: the match is the lap-1 keyframe
  /// closest to where the relocated features say the query is.
  void add_false_loop(int query, const Eigen::Vector3d& shift, int match_offset = 0) {
    RigidPose seen = gt[static_cast<std::size_t>(query)];
    seen.p -= shift;
    int best = 0;
    for (int m = 0; m < kPerLap; ++m)
      if ((gt[static_cast<std::size_t>(m)].p - seen.p).norm() < (gt[static_cast<std::size_t>(best)].p - seen.p).norm())
        best = m;
    const int match = std::min(kPerLap - 1, std::max(0, best + match_offset));
    push(query, match, compose(inverse(gt[static_cast<std::size_t>(match)]), seen), false);
  }

  /// Three true loops in lap-2 group j (queries 1, 4, 7 into the group, matches the lap-1 twin or a neighbour).
  void add_true_loops_in_group(int j, int count = 3) {
    const int q0 = kPerLap + 10 * j;
    const int offsets[] = {1, 4, 7, 2, 5, 8};
    for (int c = 0; c < count; ++c) {
      const int q = q0 + offsets[c];
      add_true_loop(q, q - kPerLap + (c % 3) - 1);
    }
  }
  void add_false_loops_in_group(int j, int count, const Eigen::Vector3d& shift) {
    const int q0 = kPerLap + 10 * j;
    for (int c = 0; c < count; ++c) add_false_loop(q0 + (c * 2) % 10, shift, c % 2);
  }

  /// Root-mean-square position error of poses against the ground truth.
  double rmse(const std::vector<RigidPose>& poses) const {
    double s = 0.0;
    for (std::size_t k = 0; k < gt.size(); ++k) s += (poses[k].p - gt[k].p).squaredNorm();
    return std::sqrt(s / static_cast<double>(gt.size()));
  }
  double end_error(const std::vector<RigidPose>& poses) const { return (poses.back().p - gt.back().p).norm(); }

 private:
  void push(int query, int match, const RigidPose& T_m_k, bool is_true) {
    VerifiedLoop l;
    l.query_t_ns = t_ns[static_cast<std::size_t>(query)];
    l.match_t_ns = t_ns[static_cast<std::size_t>(match)];
    l.p_mq = T_m_k.p;
    l.q_mq = T_m_k.q;
    l.inliers = 50;
    loops.push_back(l);
    loop_is_true.push_back(is_true);
  }
};

}  // namespace dynavins::loop::test
