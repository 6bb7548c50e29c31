#pragma once
// The stages of the visual-inertial run (DESIGN.md §2) as plain objects, each `process(input) -> output`
// (Kimera-VIO's PipelineModule without its thread): the threaded driver (run_vio) puts each on its own
// thread, the sequential driver (run_vio_sequential) calls them one after the other on the caller's thread.
// Both build them here, from the same options, so the path users run is the path the tests check.
//
//   tracker:   StereoFrame (+ its gyro samples) -> TrackedFrame
//   imu:       ImuSample | FrameTime -> PreintegratedInterval*      (linearised at the estimator's biases)
//   estimator: TrackedFrame | PreintegratedInterval -> WindowEstimate*  (pairs them, runs the window BA)
//   writer:    WindowEstimate -> the run's sinks
// Feedback: the estimator publishes its newest NavState to the IMU stage and its gyro bias to the tracker
// through LatestValue snapshots (never waited on), and the tracks it rejected to the tracker through
// RejectedTracksFeedback (waited on at rate 0, so that the run is repeatable).

#include <climits>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "messages/tracked_frame.hpp"
#include "pipeline/latest_value.hpp"
#include "pipeline/rejected_tracks_feedback.hpp"
#include "pipeline/publish_item.hpp"
#include "pipeline/vio/loop_stage.hpp"
#include "pipeline/vio/frame_imu_attacher.hpp"
#include "messages/estimator_input.hpp"
#include "stages/estimator/sliding_window_estimator.hpp"
#include "messages/window_estimate.hpp"
#include "stages/imu/frame_imu_pairer.hpp"
#include "stages/imu/imu_propagator.hpp"
#include "stages/imu/imu_stage.hpp"
#include "stages/tracker/gyro_rotation_predictor.hpp"
#include "stages/tracker/stereo_tracker.hpp"

namespace dynavins::pipeline {

struct VioRunOptions;
struct VioRunResult;

/// Tracker: the KLT front end; in mono mode the right image is ignored. With a predictor, each frame's
/// KLT starts from the rotation its gyro samples give since the previous tracked frame.
struct TrackerStage {
  TrackerStage(tracker::StereoTracker t, bool mono, std::optional<tracker::GyroRotationPredictor> g,
               LatestValue<Eigen::Vector3d>& gyro_bias,
               std::function<void(const TrackedFrame&)> on_tracked);

  TrackedFrame process(TrackerInput in);

  tracker::StereoTracker tracker;
  bool mono;
  std::optional<tracker::GyroRotationPredictor> gyro;  ///< empty: prediction off
  /// The estimator's newest gyro bias. A LatestValue has one reader and the IMU stage reads the
  /// NavState one, so the estimator publishes the bias a second time, for this stage alone.
  LatestValue<Eigen::Vector3d>& gyro_bias;
  std::function<void(const TrackedFrame&)> on_tracked;  ///< may be empty (VioSinks::tracked)
  /// The estimator's rejected tracks (rejected_feedback); null: every track counts against max_cnt.
  RejectedTracksFeedback* rejected = nullptr;
  /// Wait for the verdict on the frames before that the estimator can finish (TrackerInput::
  /// finishable_before; rate 0: repeatable); false: take the newest.
  bool wait_for_verdict = true;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  // zero until the estimator tracks
  std::optional<int64_t> prev_t_ns;
  int64_t frames_predicted = 0, frames_unpredicted = 0, features_predicted = 0, features_tracked = 0;
  int64_t features_lost_flow = 0, features_lost_back = 0;
};

/// IMU stage: before each input, linearise at the estimator's newest biases (read without waiting). The
/// estimator re-propagates an interval whose biases differ from its own, so the estimate does not depend
/// on which biases were current here.
/// With `on_imu_pose`, it also propagates the estimator's newest state through every IMU sample (the
/// IMU-rate pose, VINS-Fusion's fastPredict), but never further than `max_propagation_ns` past that
/// state: when the estimator stops tracking (reset, lost), the IMU-rate pose stops too instead of
/// dead-reckoning on.
struct ImuFeedbackStage {
  std::vector<PreintegratedInterval> process(imu::ImuStageInput in);

  imu::ImuStage stage;
  LatestValue<NavState>& latest;
  std::function<void(const PoseEstimate&, int64_t origin_ns)> on_imu_pose;  ///< may be empty
  imu::ImuPropagator propagator;
  int64_t max_propagation_ns = 500'000'000;
  int64_t propagated_from_ns = INT64_MIN;  ///< t_ns of the state the propagator was last reset to
};

/// Estimator: pairs frames with their IMU intervals, runs the window BA, publishes the newest state.
/// The keyframes that leave the window (and, at the end, those still in it) go to `on_keyframe` (the
/// loop closer), never downstream with the estimates.
struct EstimatorStage {
  std::vector<estimator::WindowEstimate> process(estimator::EstimatorInput in);
  void finish();

  imu::FrameImuPairer pairer;
  estimator::SlidingWindowEstimator estimator;
  LatestValue<NavState>& latest;
  LatestValue<Eigen::Vector3d>& gyro_bias;  ///< the same state's gyro bias, for the tracker
  int64_t tracking = 0, resets = 0;
  std::function<void(Keyframe&&)> on_keyframe = {};  ///< may be empty (no loop closure): keyframes are dropped
  RejectedTracksFeedback* rejected = nullptr;  ///< may be null: the tracker is not told
};

/// Writer: hands each estimate to the run's sink and, with `publish`, its status, window pose and weighted
/// features to the publisher.
struct WriterStage {
  void process(estimator::WindowEstimate e);

  std::function<void(const estimator::WindowEstimate&)> sink;
  std::function<void(PublishItem)> publish;  ///< may be empty
  /// With loop closure: the window state corrected by the loop closer's newest drift (nothing before the
  /// first optimisation); published as the loop-corrected pose. May be empty.
  std::function<std::optional<NavState>(const NavState&)> correct;
  int64_t frames = 0, resets = 0;
};

/// Every stage of one run and the feedback snapshots between them, built from the run's options.
/// Not copyable or movable: the stages hold references to the snapshots.
struct VioStages {
  VioStages(const VioRunOptions& options, std::function<void(const TrackedFrame&)> on_tracked,
            std::function<void(const estimator::WindowEstimate&)> on_estimate);
  VioStages(const VioStages&) = delete;
  VioStages& operator=(const VioStages&) = delete;

  /// The stages' counters, into `result` (after the last input).
  void collect(VioRunResult& result) const;

  bool predict = false;            ///< gyro-predicted KLT on (asked for, and the extrinsic is known)
  bool solver_time_budget = true;  ///< the config's max_solver_time applies (paced runs only)
  LatestValue<NavState> latest;
  LatestValue<Eigen::Vector3d> gyro_bias;
  RejectedTracksFeedback rejected;
  TrackerStage tracker;
  ImuFeedbackStage imu;
  EstimatorStage estimator;
  WriterStage writer;
  std::unique_ptr<LoopStage> loop;  ///< null when loop closure is off
};

}  // namespace dynavins::pipeline
