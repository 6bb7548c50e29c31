#pragma once
// Keeps what tests and benches score a run by, in memory: the odometry, each feature's last weight and
// label, the BA time of every solve, and the frames found at rest. Hand `record` to VioSinks::estimate.

#include <cstdint>
#include <map>
#include <vector>

#include "eval/trajectory.hpp"
#include "eval/weight_score.hpp"
#include "messages/sensor_messages.hpp"
#include "messages/window_estimate.hpp"

namespace dynavins::pipeline {

struct EstimateRecorder {
  /// One estimate (the writer's order: time order).
  void record(const estimator::WindowEstimate& e);

  eval::Trajectory estimate;                         ///< body pose of every frame while tracking
  std::map<int64_t, eval::FeatureOutcome> features;  ///< by feature id, as last seen in a window
  std::vector<double> ba_ms;                         ///< per window solve (all alternations)
  std::vector<int64_t> standstill_t_ns;              ///< frames held at rest (zero-velocity factor)
  int frames = 0, tracking_frames = 0, resets = 0;
};

/// The source's ground truth as a trajectory (time order, repeated stamps skipped).
eval::Trajectory ground_truth_trajectory(const std::vector<GroundTruthState>& states);
/// |v_wb| by time, for the states that carry a velocity.
std::map<int64_t, double> ground_truth_speed(const std::vector<GroundTruthState>& states);

}  // namespace dynavins::pipeline
