#pragma once
// Sliding-window visual-inertial bundle adjustment (VINS-Fusion's estimator, redone) with the DynaVINS
// robust feature weights (paper III). A plain object: one tracked frame plus the IMU since the previous
// frame in, one WindowEstimate out. No threads.

#include <memory>
#include <vector>

#include "stages/common/estimator_options.hpp"
#include "stages/estimator/ba_mode.hpp"
#include "messages/keyframe.hpp"
#include "messages/window_estimate.hpp"
#include "messages/tracked_frame.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::estimator {

/// What the run asks of the estimator beyond the yaml.
struct EstimatorMode {
  BaLoss loss = BaLoss::Dynavins;
  bool stereo = true;  ///< use the right camera (needs num_of_cam == 2)
};

/// Keyframes for the loop closer (paper IV, DESIGN.md §2): every frame the window kept is handed out once,
/// as a dynavins::Keyframe with its final window pose, when it leaves the window as the marginalised
/// oldest keyframe (WindowEstimate::finished_keyframes), or at the end of the run (flush_keyframes()).
/// Its points are the window features it observed (p_w from the feature's current depth, when it has one;
/// weight w_j, 1 under huber), its image the tracked frame's left image (shallow: the window holds one
/// image reference per slot, released when the frame leaves). Only frames whose pose is tracking-valid
/// are handed out. On a reset: a failure found before the frame's solve (IMU missing, gapped or not
/// continuous) emits the window's keyframes with the Reset estimate (their poses are the last Tracking
/// solve's); a failure found by the solve's own checks drops them (every slot comes from the failed solve).
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
  NavState latest_state() const;
  /// The keyframes still in the window (every slot but the newest frame, which no keyframe decision has
  /// kept yet), oldest first, none already handed out; empty unless tracking. For the end of the run: a
  /// later process() does not hand them out again.
  std::vector<Keyframe> flush_keyframes();
  bool tracking() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynavins::estimator
