#pragma once
// What the stages hand the publisher (pipeline/lcm_publisher.hpp) through its fan-in queue. Plain data.

#include <cstdint>
#include <string>
#include <variant>

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

/// One item for the publisher. `origin_ns` is the steady-clock time at which the input it comes from
/// entered its first stage (an IMU sample the IMU stage, a frame the tracker); 0 = not measured.
struct PublishItem {
  int64_t origin_ns = 0;
  std::variant<PoseEstimate, WeightedFeatureSet, StatusUpdate> payload;
};

}  // namespace dynavins::pipeline
