#pragma once
// What the estimator emits for every frame it processes: the body state of the newest frame, whether it
// became a keyframe, the window's features with their robust-BA weights, and the cost of the solve.
// Plain data.

#include <cstdint>
#include <string>
#include <vector>

#include "messages/estimate_messages.hpp"
#include "messages/keyframe.hpp"

namespace dynavins::estimator {

/// Cost and shape of one window solve (all alternations together).
struct SolveStats {
  double total_ms = 0;   ///< the whole process() call
  double ba_ms = 0;      ///< Ceres solves + weight steps (what the paper's "BA time" measures)
  double weight_ms = 0;  ///< closed-form weight steps only
  double marginalization_ms = 0;
  int alternations = 0;        ///< weight step + state solve pairs (1 for huber)
  int ceres_iterations = 0;    ///< summed over alternations
  int features_in_window = 0;  ///< features with a depth estimate used in the solve
};

enum class EstimatorStatus : int8_t {
  Initializing = 0,  ///< no pose yet (collecting the first window)
  Tracking = 1,      ///< state valid
  Reset = 2,         ///< failure detected on this frame; the window was cleared, re-initialising
};

struct WindowEstimate {
  int64_t t_ns = 0;
  int64_t seq = 0;  ///< the tracked frame's seq
  EstimatorStatus status = EstimatorStatus::Initializing;
  NavState state;               ///< body in world at t_ns; valid when status == Tracking
  bool keyframe = false;        ///< the previous newest frame was kept as a keyframe (VINS' MARGIN_OLD)
  bool standstill = false;      ///< found at rest: its velocity was held at zero (standstill_detector.hpp)
  /// The weights were judged on the IMU-only path from the last rest (zupt_imu, imu_path_from_rest.hpp), a
  /// path that drifts with the accelerometer bias: verdicts the tracker is not told (rejected_feedback).
  bool judged_on_rest_path = false;
  WeightedFeatureSet features;  ///< window features, weights after this solve (Tracking only)
  SolveStats solve;
  std::string event;  ///< "initialized", "reset: <reason>", or empty
  int64_t received_ns = 0;  ///< the frame's TrackedFrame::received_ns (latency accounting only)
  /// Keyframes that left the window on this frame (loop closer input), oldest first: the oldest keyframe
  /// when it is marginalised (keyframe == true while Tracking), or, on a Reset found before this frame's
  /// solve (IMU missing or gapped), every keyframe the window held (see SlidingWindowEstimator).
  std::vector<Keyframe> finished_keyframes;  // keyframes that left the window on this frame (loop closer input)
};

}  // namespace dynavins::estimator
