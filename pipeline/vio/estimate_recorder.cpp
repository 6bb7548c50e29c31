#include "pipeline/vio/estimate_recorder.hpp"

namespace dynavins::pipeline {

void EstimateRecorder::record(const estimator::WindowEstimate& e) {
  ++frames;
  if (e.status == estimator::EstimatorStatus::Reset) ++resets;
  if (e.status != estimator::EstimatorStatus::Tracking) return;
  ++tracking_frames;
  if (e.standstill) standstill_t_ns.push_back(e.t_ns);
  estimate.poses.push_back(eval::stamped_pose(e.t_ns, e.state.p_wb, e.state.q_wb));
  if (e.solve.alternations > 0) ba_ms.push_back(e.solve.ba_ms);
  for (const auto& wf : e.features.features) features[wf.id] = {wf.weight, wf.sim_label, wf.times_solved};
}

eval::Trajectory ground_truth_trajectory(const std::vector<GroundTruthState>& states) {
  eval::Trajectory t;
  for (const GroundTruthState& g : states)
    if (t.poses.empty() || g.t_ns > t.poses.back().t_ns) t.poses.push_back(eval::stamped_pose(g.t_ns, g.p_wb, g.q_wb));
  return t;
}

std::map<int64_t, double> ground_truth_speed(const std::vector<GroundTruthState>& states) {
  std::map<int64_t, double> speed;
  for (const GroundTruthState& g : states)
    if (g.has_velocity) speed[g.t_ns] = g.v_wb.norm();
  return speed;
}

}  // namespace dynavins::pipeline
