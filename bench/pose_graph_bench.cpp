// Pose-graph solve time as the graph grows (paper IV-C; issue 21, speed and scale): LoopGraphOptimizer on
// synthetic graphs of N keyframes, every mode. The path drives laps of a 200 m circle (a keyframe every
// 0.5 m, 400 a lap); the odometry integrates the true motion with yaw drift and a scale error; from the
// second lap on every keyframe closes one true loop to its twin of the first lap (0.3 m inside), and one
// group in ten also holds a persistent false hypothesis (5 loops against an object moved 4 m). Groups of
// 10 keyframes. Prints, per N, the solve time of each mode and the position RMSE before and after.
// With --incremental N the graph grows as the loop stage grows it: ten keyframes (one group) at a time,
// an optimisation (dynavins) after each group that brought loops, each warm-started from the previous one
// (LoopCloserOptions::warm_start; redone from the odometry when it rejects a new group) and, with --cold,
// beside it the same sequence started from the odometry every time. Prints per 500 keyframes the
// optimisations, the warm ones redone cold, their mean and max time and the RMSE at the end.
// Usage: bench_pose_graph [N ...]   (default 250 500 1000 2000 4000)
//        bench_pose_graph --incremental N [--cold]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

/// One optimiser fed group by group, optimising after each group that brought loops.
struct GrowingGraph {
  LoopGraphOptimizer optimizer;
  LoopGraphResult last;
  bool warm = true;
  int optimizations = 0, cold_restarts = 0;
  double ms_sum = 0.0, ms_max = 0.0;

  void optimize() {
    const auto t0 = std::chrono::steady_clock::now();
    last = optimizer.optimize(LoopMode::Dynavins, warm && optimizations > 0 ? &last : nullptr);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++optimizations, ms_sum += ms, ms_max = std::max(ms_max, ms);
    if (last.cold_restart) ++cold_restarts;
  }
  void restart_bucket() { optimizations = 0, cold_restarts = 0, ms_sum = 0.0, ms_max = 0.0; }
};

double rmse_prefix(const SyntheticGraph& g, const std::vector<RigidPose>& poses) {
  double s = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) s += (poses[k].p - g.truth[k].p).squaredNorm();
  return poses.empty() ? 0.0 : std::sqrt(s / static_cast<double>(poses.size()));
}

int run_incremental(int n, bool cold) {
  const SyntheticGraph g = make_graph(n);
  std::vector<GrowingGraph> runs(cold ? 2 : 1);
  if (cold) runs[1].warm = false;
  std::printf("%10s %13s %13s %13s %12s %10s", "keyframes", "optimisations", "cold_restarts", "warm_mean_ms",
              "warm_max_ms", "rmse_warm");
  if (cold) std::printf(" %13s %12s %10s", "cold_mean_ms", "cold_max_ms", "rmse_cold");
  std::printf("\n");
  std::size_t next_loop = 0;
  for (std::size_t grp = 0; grp < g.groups.size(); ++grp) {
    const int first = static_cast<int>(grp) * 10;
    bool loops = false;
    for (GrowingGraph& r : runs) {
      for (int k = first; k < first + 10; ++k)
        r.optimizer.add_keyframe(g.t_ns[static_cast<std::size_t>(k)], g.odometry[static_cast<std::size_t>(k)]);
      r.optimizer.add_group(g.groups[grp]);
      std::size_t l = next_loop;
      for (; l < g.loops.size() && g.loops[l].query_t_ns <= g.groups[grp].t_ns.back(); ++l)
        r.optimizer.add_loop(g.loops[l]);
      loops = l > next_loop;
      if (&r == &runs.back()) next_loop = l;
      if (loops) r.optimize();
    }
    const int kf = first + 10;
    if (kf % 500 != 0 && grp + 1 != g.groups.size()) continue;
    std::printf("%10d %13d %13d %13.1f %12.1f %10.3f", kf, runs[0].optimizations, runs[0].cold_restarts,
                runs[0].optimizations ? runs[0].ms_sum / runs[0].optimizations : 0.0, runs[0].ms_max,
                rmse_prefix(g, runs[0].last.poses));
    if (cold)
      std::printf(" %13.1f %12.1f %10.3f", runs[1].optimizations ? runs[1].ms_sum / runs[1].optimizations : 0.0,
                  runs[1].ms_max, rmse_prefix(g, runs[1].last.poses));
    std::printf("\n");
    std::fflush(stdout);
    for (GrowingGraph& r : runs) r.restart_bucket();
  }
  return 0;
}

int main(int argc, char** argv) {
  if (argc >= 3 && std::strcmp(argv[1], "--incremental") == 0) {
    const int n = std::atoi(argv[2]);
    if (n < 20) {
      std::fprintf(stderr, "bench_pose_graph: --incremental N needs N >= 20 (got %s)\n", argv[2]);
      return 2;
    }
    return run_incremental(n, argc >= 4 && std::strcmp(argv[3], "--cold") == 0);
  }
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
