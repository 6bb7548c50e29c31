#pragma once
// What the stages hand the publisher (pipeline/lcm_publisher.hpp) through its fan-in queue. Plain data.

#include <cstdint>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "messages/estimate_messages.hpp"
#include "messages/window_estimate.hpp"

namespace dynavins::pipeline {

/// The estimator's status as it is published (status_t).
struct StatusUpdate {
  int64_t t_ns = 0;
  estimator::EstimatorStatus status = estimator::EstimatorStatus::Initializing;
  std::string reason;  ///< the estimate's event ("initialized", "reset: ..."), or empty
  int64_t frames = 0;  ///< frames estimated so far
  int64_t resets = 0;  ///< resets so far
};

/// The keyframe path after a pose-graph optimisation (path_t).
struct PathUpdate {
  int64_t t_ns = 0;                 ///< newest keyframe
  std::vector<PoseEstimate> poses;  ///< every keyframe, loop-corrected
};

/// The hypotheses of one keyframe group after an optimisation (loop_hypotheses_t).
struct HypothesesUpdate {
  struct Hypothesis {
    float weight = 0.f;
    NavState first_keyframe;  ///< the group's first keyframe C_i after the optimisation
    std::vector<std::pair<int64_t, int64_t>> loops;  ///< (query C_k, match C_m) times
  };
  int64_t t_ns = 0;              ///< newest keyframe
  int64_t group_first_t_ns = 0;  ///< C_i
  int32_t group_size = 0;
  std::vector<Hypothesis> hypotheses;  ///< H^0, H^1
};

/// One item for the publisher. `origin_ns` is the steady-clock time at which the input it comes from
/// entered its first stage (an IMU sample the IMU stage, a frame the tracker); 0 = not measured.
struct PublishItem {
  int64_t origin_ns = 0;
  std::variant<PoseEstimate, WeightedFeatureSet, StatusUpdate, PathUpdate, HypothesesUpdate> payload;
};

}  // namespace dynavins::pipeline
