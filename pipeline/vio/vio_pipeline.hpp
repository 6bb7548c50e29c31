#pragma once
// The visual-inertial run (DESIGN.md §2) wired on pipeline::Pipeline, one thread per box:
//
//   replay ─┬─ stereo frames + their gyro samples (SPSC, 8) ──▶ tracker ── tracked frames ──┐
//           │                                                      ▲                        ▼ (fan-in)
//           └─ IMU + frame times (SPSC, 4000) ──▶ imu ── intervals ┼─────────────────▶ estimator ── estimates ──▶ writer
//                                                  ▲ │             └─ gyro bias ───────────┤ (LatestValue)   │
//                                                  └─┼─ latest NavState ───────────────────┘ (LatestValue)   │
//                                                    └── IMU-rate pose ──▶ publisher (LCM) ◀── window pose, ─┘
//                                                        (fan-in, 4096, drops when full)      features, status
//
// Gyro prediction (on by default): the replay packs each frame with the IMU samples of its interval
// (FrameImuAttacher), the tracker integrates them (GyroRotationPredictor, minus the estimator's newest gyro
// bias) and seeds its KLT with the rotation. A frame whose interval is not covered (the first, one after a
// dropped frame, an IMU outage) is tracked without prediction and counted.
//
// rate 0: every queue blocks (lossless, repeatable); rate > 0: the frame queue drops the oldest frames
// when the tracker falls behind (counted). IMU is never dropped: a full IMU queue in real time is an error.
// End of input, SIGINT or a stop request drain every queue before run_vio() returns.
//
// run_vio_sequential() is the same run on the caller's thread (Kimera-VIO's spinSequential beside
// launchThreads): the same stages (vio_stages.hpp), built the same way, fed in the replay's order, with no
// queues between them. At rate 0 both give the same trajectory bit for bit (tests/vio/test_vio_sequential.cpp);
// tests and benches that need one answer every time, or a hook after the tracker, use it.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/sensor_source.hpp"
#include "messages/tracked_frame.hpp"
#include "pipeline/lcm_publisher.hpp"
#include "pipeline/vio/loop_stage.hpp"
#include "stages/loop/graph/loop_mode.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/replay.hpp"
#include "pipeline/stop_flag.hpp"
#include "stages/common/estimator_options.hpp"
#include "stages/estimator/sliding_window_estimator.hpp"
#include "messages/window_estimate.hpp"
#include "stages/imu/frame_imu_pairer.hpp"
#include "stages/imu/imu_stage.hpp"

namespace dynavins::pipeline {

/// What one run does.
struct VioRunOptions {
  EstimatorOptions estimator;        ///< the loaded yaml (with any --set overrides)
  estimator::EstimatorMode mode;     ///< BA loss, stereo or mono
  double rate = 0.0;                 ///< x real time; 0 = as fast as possible, lossless
  /// The source is live (it delivers in real time by itself): no pacing, but real-time back-pressure
  /// (oldest frames dropped when the tracker falls behind, solver time budget on). rate must be 0.
  bool live = false;
  bool real_time() const { return rate > 0 || live; }
  bool show_progress = true;         ///< replay progress line on the terminal
  double imu_rate_hz = 200.0;        ///< nominal IMU rate (gap detection)
  imu::ImuNoiseConvention imu_noise = imu::ImuNoiseConvention::VinsFusion;
  std::size_t frame_queue = 8;       ///< stereo frames waiting for the tracker
  std::size_t imu_queue = 4000;      ///< IMU samples and frame times waiting for the IMU stage
  std::size_t estimator_queue = 64;  ///< tracked frames and intervals waiting for the estimator
  std::size_t output_queue = 64;     ///< estimates waiting for the writer
  /// Seed the tracker's KLT with the gyro-integrated rotation (off by default: the gyro bias comes from
  /// the estimator thread, so a run then depends on thread timing and is no longer bit-repeatable).
  bool gyro_prediction = false;
  /// Publish on LCM while running (lcm_publisher.hpp); empty = publish nothing. Threaded run only.
  std::string lcm_url;
  PublisherChannels channels;
  std::size_t publish_queue = 4096;  ///< items waiting for the publisher; a full queue drops (counted)
  /// Loop closure (paper IV) on the keyframes the estimator lets go: Off runs no loop stage (the
  /// trajectory is the odometry). `vocabulary` is the vocabulary tree file the place recognition uses.
  loop::LoopMode loop_mode = loop::LoopMode::Off;
  std::string vocabulary;
  /// Keyframes waiting for the loop closer; rate 0 blocks (lossless), real time drops (counted).
  std::size_t keyframe_queue = 64;
  /// Real-time runs only: SCHED_FIFO priority of the source (sensor input), IMU and publisher threads, all
  /// light, when the process may (0 = off): on a busy machine the IMU-rate pose is then not held up behind
  /// the tracker and estimator, and a live source keeps draining its socket (bench/lcm_bench.sh).
  int realtime_priority = 10;
};

/// Where the results go. Threaded: `estimate` is called on the writer thread, `tracked` on the tracker
/// thread; sequential: both on the caller's. Either may be empty.
struct VioSinks {
  /// One call per processed frame, in time order.
  std::function<void(const estimator::WindowEstimate&)> estimate;
  /// Every tracked frame, right after the tracker (e.g. to score tracks against simulator truth).
  std::function<void(const TrackedFrame&)> tracked;
  /// Every keyframe the estimator lets go (the loop closer's input; also the window's last keyframes at
  /// the end), on the estimator's thread, before the loop closer gets it.
  std::function<void(const Keyframe&)> keyframe;
};

/// Everything a run measured; the stage counters are read after all threads have ended.
struct VioRunResult {
  RunReport report;        ///< per-thread timing, per-queue depth and drops, error, interrupted
  ReplayStats replay;      ///< events replayed, sensor time covered
  std::string source;      ///< the source's description
  int64_t frames_dropped = 0;   ///< stereo frames lost in the frame queue (rate > 0 only)
  int64_t frames_tracked = 0;   ///< frames the tracker processed
  int64_t frames_estimated = 0; ///< frames the estimator processed (= estimates written)
  int64_t frames_tracking = 0;  ///< estimates with status Tracking
  int64_t resets = 0;           ///< estimates with status Reset
  /// Gyro prediction: frames tracked with and without a predicted rotation (the first frame, one after a
  /// dropped frame or an IMU outage), and features whose KLT converged from the prediction (all 0 when off;
  /// TrackerStats::predicted, counted before the min-distance mask, so it may exceed features_tracked).
  bool gyro_prediction = false;
  /// Whether the config's max_solver_time bounded the window solves (paced runs); at rate 0 only the
  /// iteration budget does, so the result does not depend on the machine's speed or load.
  bool solver_time_budget = true;
  /// Threads that asked for real-time scheduling (VioRunOptions::realtime_priority) and got it / were refused.
  int realtime_threads = 0;
  int realtime_refused = 0;
  int64_t frames_gyro_predicted = 0;
  int64_t frames_gyro_unpredicted = 0;
  int64_t features_gyro_predicted = 0;
  int64_t features_tracked = 0;    ///< features carried over from the previous frame, summed over frames
  int64_t features_lost_flow = 0;  ///< tracks lost by KLT (failed or left the image), summed over frames
  int64_t features_lost_back = 0;  ///< tracks lost by the forward-backward check, summed over frames
  imu::ImuStageStats imu;
  imu::ImuIntervalBuilderStats imu_builder;
  imu::FrameImuPairerStats pairer;
  std::vector<GroundTruthState> ground_truth;  ///< the source's ground truth, in time order
  std::optional<PublisherStats> publisher;     ///< what was published (with lcm_url)
  int64_t publish_dropped = 0;                 ///< items the full publish queue dropped
  std::optional<LoopRunSummary> loop;          ///< what the loop closer did (loop_mode != Off)
  bool interrupted() const { return report.interrupted || replay.stopped; }
};

/// Throws std::invalid_argument naming the problem when `options` cannot run (stereo without cam1,
/// no IMU, negative rate, zero queue capacity). run_vio() calls it first; callers may call it before
/// creating outputs.
void check_vio_options(const VioRunOptions& options);

/// Runs `source` through tracker, IMU stage and estimator until its end, SIGINT or `external_stop`
/// (may be null; polled by the replay thread). Blocks until every thread has ended. Throws
/// std::invalid_argument for options that cannot run (stereo without cam1, no IMU); a failure inside
/// a thread is returned in result.report (ok == false, error, failed_thread).
VioRunResult run_vio(io::SensorSource& source, const VioRunOptions& options, const VioSinks& sinks,
                    const StopFlag* external_stop = nullptr);

/// The same run on the caller's thread, one input at a time in the replay's order (rate must be 0).
/// Stops at the source's end, SIGINT or `external_stop`. A stage's exception is returned in result.report
/// like run_vio's (failed_thread names the stage); result.report.stages/queues stay empty.
VioRunResult run_vio_sequential(io::SensorSource& source, const VioRunOptions& options, const VioSinks& sinks,
                              const StopFlag* external_stop = nullptr);

}  // namespace dynavins::pipeline
