#include "pipeline/vio/loop_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pipeline/report_format.hpp"
#include "stages/loop/graph/loop_mode.hpp"

namespace dynavins::pipeline {
namespace {

loop::RigidPose rigid(const eval::StampedPose& p) { return loop::RigidPose{p.p, p.q}; }

/// The ground-truth pose nearest to t_ns, if one lies within 10 ms (truth sorted by time).
std::optional<loop::RigidPose> truth_at(const eval::Trajectory& truth, int64_t t_ns) {
  const auto it = std::lower_bound(truth.poses.begin(), truth.poses.end(), t_ns,
                                   [](const eval::StampedPose& p, int64_t t) { return p.t_ns < t; });
  const eval::StampedPose* best = nullptr;
  if (it != truth.poses.end()) best = &*it;
  if (it != truth.poses.begin() && (!best || t_ns - std::prev(it)->t_ns < best->t_ns - t_ns)) best = &*std::prev(it);
  if (!best || std::llabs(best->t_ns - t_ns) > 10'000'000) return std::nullopt;
  return rigid(*best);
}

}  // namespace

eval::Trajectory corrected_trajectory(const eval::Trajectory& odometry, const LoopRunSummary* loop) {
  if (!loop) return odometry;
  std::vector<loop::StampedPose> in;
  in.reserve(odometry.poses.size());
  for (const eval::StampedPose& p : odometry.poses) in.push_back(loop::StampedPose{p.t_ns, rigid(p)});
  eval::Trajectory out;
  out.source = odometry.source;
  for (const loop::StampedPose& p : loop::correct_trajectory(in, loop->corrections))
    out.poses.push_back(eval::stamped_pose(p.t_ns, p.T_W_b.p, p.T_W_b.q));
  return out;
}

LoopTruthCounts write_loops_csv(const std::string& path, const LoopRunSummary& loop, const eval::Trajectory& truth) {
  std::ofstream f(path, std::ios::out | std::ios::trunc);
  f << "mode,query_t_ns,match_t_ns,inliers,group,group_first_t_ns,hypothesis,weight,used,true_loop,error_m,error_deg\n";
  LoopTruthCounts c;
  for (std::size_t i = 0; i < loop.rows.size(); ++i) {
    const loop::LoopReportRow& r = loop.rows[i];
    f << loop::loop_mode_name(loop.mode) << ',' << r.query_t_ns << ',' << r.match_t_ns << ',' << r.inliers << ','
      << r.group << ',' << r.group_first_t_ns << ',' << r.hypothesis << ',' << r.weight << ',' << (r.used ? 1 : 0);
    const auto m = truth_at(truth, r.match_t_ns), q = truth_at(truth, r.query_t_ns);
    if (m && q && i < loop.loops.size()) {
      // T_m^k from the truth against the loop's (eq. 13's relative pose).
      const loop::RigidPose truth_mq = loop::compose(loop::inverse(*m), *q);
      const VerifiedLoop& l = loop.loops[i];
      const double err_m = (truth_mq.p - l.p_mq).norm();
      const double err_deg = truth_mq.q.angularDistance(l.q_mq) * 180.0 / M_PI;
      const bool is_true = err_m < kTrueLoopMaxErrorM && err_deg < kTrueLoopMaxErrorDeg;
      (is_true ? c.true_loops : c.false_loops)++;
      if (r.used && r.weight >= 0.5) ++(is_true ? c.true_used : c.false_used);
      if (r.weight >= 0.5) ++(is_true ? c.true_adopted : c.false_adopted);
      f << ',' << (is_true ? 1 : 0) << ',' << err_m << ',' << err_deg << '\n';
    } else {
      f << ",,,\n";
    }
  }
  f.flush();
  if (!f) throw std::runtime_error(path + ": writing the loops failed");
  return c;
}

std::string loop_json(const LoopRunSummary& l, const LoopTruthCounts& t, bool has_truth) {
  std::ostringstream j;
  j << "{\"mode\": " << json_string(loop::loop_mode_name(l.mode)) << ", \"vocabulary\": " << json_string(l.vocabulary)
    << ", \"keyframes\": " << l.keyframes << ", \"keyframes_dropped\": " << l.keyframes_dropped
    << ", \"loops\": " << l.loops.size() << ", \"groups\": " << l.groups << ", \"optimizations\": " << l.optimizations
    << ", \"keyframe_ms_mean\": " << l.keyframe_ms_mean << ", \"keyframe_ms_p95\": " << l.keyframe_ms_p95
    << ", \"keyframe_ms_max\": " << l.keyframe_ms_max << ", \"keyframe_cpu_ms_mean\": " << l.keyframe_cpu_ms_mean
    << ", \"descriptors_ms_mean\": " << l.descriptors_ms_mean << ", \"query_ms_mean\": " << l.query_ms_mean
    << ", \"verification_ms_mean\": " << l.verification_ms_mean
    << ", \"optimization_ms_mean\": " << l.optimization_ms_mean
    << ", \"optimization_ms_max\": " << l.optimization_ms_max << ", \"memory_kb\": " << l.memory_bytes / 1024.0
    << ", \"keyframes_released\": " << l.keyframes_released
    << ", \"correction_applied\": " << (l.correction_applied ? "true" : "false");
  if (has_truth)
    j << ", \"true_loops\": " << t.true_loops << ", \"false_loops\": " << t.false_loops
      << ", \"false_loops_used\": " << t.false_used << ", \"true_loops_used\": " << t.true_used
      << ", \"false_loops_adopted\": " << t.false_adopted << ", \"true_loops_adopted\": " << t.true_adopted;
  j << "}";
  return j.str();
}

}  // namespace dynavins::pipeline
