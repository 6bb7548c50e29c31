#pragma once
// Sliding-window visual-inertial bundle adjustment (VINS-Fusion's estimator, redone) with the DynaVINS
// robust feature weights (paper III). A plain object: one tracked frame plus the IMU since the previous
// frame in, one WindowEstimate out. No threads.

#include <memory>

#include "stages/common/estimator_options.hpp"
#include "stages/estimator/ba_mode.hpp"
#include "messages/window_estimate.hpp"
#include "messages/tracked_frame.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::estimator {

/// What the run asks of the estimator beyond the yaml.
struct EstimatorMode {
  BaLoss loss = BaLoss::Dynavins;
  bool stereo = true;  ///< use the right camera (needs num_of_cam == 2)
};

class SlidingWindowEstimator {
 public:
  SlidingWindowEstimator(const EstimatorOptions& options, EstimatorMode mode);
  ~SlidingWindowEstimator();
  SlidingWindowEstimator(SlidingWindowEstimator&&) noexcept;
  SlidingWindowEstimator& operator=(SlidingWindowEstimator&&) noexcept;

  /// Processes the next frame. `imu` covers (previous frame time, frame.t_ns]; null for the very first
  /// frame (or after an IMU outage, which resets the estimator and is reported in the event).
  WindowEstimate process(const TrackedFrame& frame, const PreintegratedInterval* imu);

  /// The newest frame's state (for IMU-rate propagation); valid once tracking.
  NavState latestState() const;
  bool tracking() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynavins::estimator
