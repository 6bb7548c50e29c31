#pragma once
// The loop-closure stage of the run (paper IV, DESIGN.md §2): keyframes the estimator let go, in time
// order, into loop::LoopCloser; after the last one, the final optimisation. A plain object with
// process()/finish(): run_vio runs it on its own thread behind the keyframe queue, run_vio_sequential calls
// it in line. What it found (corrections for every keyframe, the verified loops with their final
// weights) is collected into the run's result for trajectory.tum and loops.csv.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "messages/keyframe.hpp"
#include "stages/loop/graph/loop_mode.hpp"
#include "stages/loop/graph/loop_report.hpp"
#include "stages/loop/trajectory_correction.hpp"

namespace dynavins {
class CameraModel;
}
namespace dynavins::loop {
class LoopCloser;
struct LoopCloserOutput;
}  // namespace dynavins::loop

namespace dynavins::pipeline {

/// What the loop closer did in one run (summary.json "loop", trajectory.tum, loops.csv).
struct LoopRunSummary {
  loop::LoopMode mode = loop::LoopMode::Off;
  std::string vocabulary;
  int64_t keyframes = 0;          ///< keyframes processed
  int64_t keyframes_dropped = 0;  ///< real time only: the keyframe queue was full (the chain skips them)
  int64_t groups = 0, optimizations = 0;
  double keyframe_ms_mean = 0, keyframe_ms_max = 0;  ///< process() per keyframe, optimisation included
  double keyframe_ms_p95 = 0;                        ///< 95th percentile of the same
  /// The loop thread's own CPU time per keyframe (CLOCK_THREAD_CPUTIME_ID): unlike the wall-clock figures
  /// above it does not grow when the machine is shared (OpenCV's worker threads, if any, not counted).
  double keyframe_cpu_ms_mean = 0;
  /// Means per keyframe of its parts: ORB descriptors, bag of words + database query, PnP verification of
  /// the candidates; and the pose-graph optimisation's mean over the optimisations that ran.
  double descriptors_ms_mean = 0, query_ms_mean = 0, verification_ms_mean = 0, optimization_ms_mean = 0;
  double optimization_ms_max = 0;
  std::size_t memory_bytes = 0;                       ///< the keyframe database, no images
  /// The final optimisation moved the trajectory (false: off, no optimisation, or the correction was
  /// insignificant against the odometry, LoopGraphOptions::skip_insignificant_correction).
  bool correction_applied = false;
  int64_t keyframes_released = 0;  ///< taken out of the database as revisits (LoopCloserOptions::release_revisited)
  std::vector<loop::KeyframeCorrection> corrections;  ///< per keyframe, after the final optimisation
  std::vector<VerifiedLoop> loops;                    ///< every verified loop, in detection order
  std::vector<loop::LoopReportRow> rows;              ///< per loop: group, hypothesis, final weight, used
};

class LoopStage {
 public:
  /// Loads the vocabulary (std::runtime_error naming the file) and builds the loop closer; `camera`
  /// undistorts the extra corners it detects for PnP.
  LoopStage(loop::LoopMode mode, const std::string& vocabulary_path, std::shared_ptr<const CameraModel> camera);
  ~LoopStage();
  LoopStage(const LoopStage&) = delete;
  LoopStage& operator=(const LoopStage&) = delete;

  void process(Keyframe keyframe);
  void finish();
  /// After the last input.
  LoopRunSummary summary() const;
  /// The loop closer itself (its loops and groups), for on_output on the loop stage's thread.
  const loop::LoopCloser& closer() const { return *closer_; }

  /// Each output of the loop closer (publisher: path, hypotheses, drift); may be empty.
  std::function<void(const loop::LoopCloserOutput&)> on_output;
  int64_t dropped = 0;  ///< set by the wiring (keyframes it could not queue)

 private:
  void account(const loop::LoopCloserOutput& out, double ms);

  loop::LoopMode mode_;
  std::string vocabulary_path_;
  std::unique_ptr<loop::LoopCloser> closer_;
  int64_t keyframes_ = 0;
  double ms_sum_ = 0, ms_max_ = 0, opt_ms_max_ = 0, cpu_ms_sum_ = 0;
  std::vector<double> keyframe_ms_;  // per keyframe (8 bytes each), for the p95
  double descriptors_ms_sum_ = 0, query_ms_sum_ = 0, verification_ms_sum_ = 0, opt_ms_sum_ = 0;
};

}  // namespace dynavins::pipeline
