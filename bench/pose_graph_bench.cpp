// Pose-graph solve time as the graph grows (paper IV-C; issue 21, speed and scale): LoopGraphOptimizer on
// synthetic graphs of N keyframes, every mode. The path drives laps of a 200 m circle (a keyframe every
// 0.5 m, 400 a lap); the odometry integrates the true motion with yaw drift and a scale error; from the
// second lap on every keyframe closes one true loop to its twin of the first lap (0.3 m inside), and one
// group in ten also holds a persistent false hypothesis (5 loops against an object moved 4 m). Groups of
// 10 keyframes. Prints, per N, the solve time of each mode and the position RMSE before and after.
// Usage: bench_pose_graph [N ...]   (default 250 500 1000 2000 4000)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "stages/loop/graph/loop_graph_optimizer.hpp"
#include "stages/loop/graph/rigid_pose.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {

constexpr int kPerLap = 400;
constexpr double kRadius = 200.0 / (2.0 * M_PI);

struct SyntheticGraph {
  std::vector<int64_t> t_ns;
  std::vector<RigidPose> truth, odometry;
  std::vector<KeyframeGroup> groups;
  std::vector<VerifiedLoop> loops;
};

RigidPose circle_pose(int k) {
  const int lap = k / kPerLap;
  const double a = 2.0 * M_PI * (k % kPerLap) / kPerLap;
  const double r = kRadius - (lap > 0 ? 0.3 : 0.0);
  return RigidPose{Eigen::Vector3d(r * std::sin(a), kRadius - r * std::cos(a), 0.1 * std::sin(0.05 * k)),
                   quat_from_ypr(a, 0.0, 0.0)};
}

VerifiedLoop loop_between(const SyntheticGraph& g, int query, int match, const RigidPose& T_W_query_seen) {
  const RigidPose T_m_k = compose(inverse(g.truth[static_cast<std::size_t>(match)]), T_W_query_seen);
  VerifiedLoop l;
  l.query_t_ns = g.t_ns[static_cast<std::size_t>(query)];
  l.match_t_ns = g.t_ns[static_cast<std::size_t>(match)];
  l.p_mq = T_m_k.p;
  l.q_mq = T_m_k.q;
  l.inliers = 40;
  return l;
}

SyntheticGraph make_graph(int n) {
  SyntheticGraph g;
  for (int k = 0; k < n; ++k) {
    g.t_ns.push_back(1'000'000'000LL + 100'000'000LL * k);
    g.truth.push_back(circle_pose(k));
  }
  // Odometry: the true relative motion scaled by 1.01, yaw drifting 0.02 deg per keyframe.
  g.odometry.push_back(g.truth[0]);
  for (int k = 1; k < n; ++k) {
    const RigidPose d =
        compose(inverse(g.truth[static_cast<std::size_t>(k - 1)]), g.truth[static_cast<std::size_t>(k)]);
    RigidPose next = compose(g.odometry.back(), RigidPose{1.01 * d.p, d.q});
    next.q = quat_from_ypr(yaw_of(next.q) + 0.02 * M_PI / 180.0, pitch_of(next.q), roll_of(next.q));
    g.odometry.push_back(next);
  }
  for (int first = 0; first + 10 <= n; first += 10) {
    KeyframeGroup grp;
    for (int k = first; k < first + 10; ++k) grp.t_ns.push_back(g.t_ns[static_cast<std::size_t>(k)]);
    g.groups.push_back(grp);
  }
  for (int k = kPerLap; k < n; ++k) {
    const int twin = k % kPerLap;
    g.loops.push_back(loop_between(g, k, twin, g.truth[static_cast<std::size_t>(k)]));
    if ((k / 10) % 10 == 0 && k % 10 < 5) {  // a relocated object: C_k seen 4 m from where it is
      RigidPose seen = g.truth[static_cast<std::size_t>(k)];
      seen.p += Eigen::Vector3d(4.0, 0.0, 0.0);
      g.loops.push_back(loop_between(g, k, twin, seen));
    }
  }
  return g;
}

double rmse(const SyntheticGraph& g, const std::vector<RigidPose>& poses) {
  double s = 0.0;
  for (std::size_t k = 0; k < g.truth.size(); ++k) s += (poses[k].p - g.truth[k].p).squaredNorm();
  return std::sqrt(s / static_cast<double>(g.truth.size()));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {250, 500, 1000, 2000, 4000};
  std::printf("%8s %7s %11s %12s %14s %12s %10s %9s %9s %9s\n", "keyframes", "loops", "all_ms", "switch_ms",
              "dynavins_ms", "alternations", "rmse_odom", "rmse_all", "rmse_sw", "rmse_dyn");
  for (int n : sizes) {
    if (n < 20) {
      std::fprintf(stderr, "bench_pose_graph: N must be >= 20 (got %d)\n", n);
      return 2;
    }
    const SyntheticGraph g = make_graph(n);
    LoopGraphOptimizer opt;
    for (std::size_t k = 0; k < g.t_ns.size(); ++k) opt.add_keyframe(g.t_ns[k], g.odometry[k]);
    for (const KeyframeGroup& grp : g.groups) opt.add_group(grp);
    for (const VerifiedLoop& l : g.loops) opt.add_loop(l);
    double ms[3] = {0, 0, 0}, err[3] = {0, 0, 0};
    int alternations = 0;
    const LoopMode modes[3] = {LoopMode::All, LoopMode::Switchable, LoopMode::Dynavins};
    for (int m = 0; m < 3; ++m) {
      const auto t0 = std::chrono::steady_clock::now();
      const LoopGraphResult r = opt.optimize(modes[m]);
      ms[m] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      err[m] = rmse(g, r.poses);
      if (modes[m] == LoopMode::Dynavins) alternations = r.alternations;
    }
    std::printf("%8d %7zu %11.1f %12.1f %14.1f %12d %10.3f %9.3f %9.3f %9.3f\n", n, g.loops.size(), ms[0], ms[1], ms[2],
                alternations, rmse(g, g.odometry), err[0], err[1], err[2]);
    std::fflush(stdout);
  }
  return 0;
}
