#pragma once
// The replay driver: takes a recorded SensorSource and hands its events, in time order, to the
// pipeline's input queues, paced at `rate` x real time (rate 0: as fast as the pipeline takes them;
// the queues then block, so the replay is lossless and repeatable). It measures its own pacing
// error (how late each event left against its schedule) and shows progress.

#include <functional>

#include "io/sensor_source.hpp"
#include "pipeline/latency_histogram.hpp"
#include "pipeline/stop_flag.hpp"

namespace dynavins::pipeline {

struct ReplayOptions {
  double rate = 0.0;         ///< x real time; 0 = as fast as possible
  bool show_progress = true;
};

/// Where events go. Each returns false if the event was not taken (run aborted).
struct ReplaySinks {
  std::function<bool(StereoFrame&&)> frame;
  std::function<bool(ImuSample&&)> imu;
  std::function<bool(GroundTruthState&&)> ground_truth;  ///< may be empty: ground truth is then dropped
};

struct ReplayStats {
  int64_t frames = 0, imu = 0, ground_truth = 0;
  double sensor_s = 0.0;  ///< sensor time covered
  double wall_s = 0.0;
  /// Paced runs: |actual - scheduled| hand-over time per event (scheduling error of the driver alone).
  LatencySummary pacing_error;
  bool stopped = false;   ///< ended by stop request (SIGINT), not by the end of the data
};

/// Replays `source` into `sinks` until its end or `stop`. Throws what the source throws.
ReplayStats replay(io::SensorSource& source, const ReplayOptions& options, const ReplaySinks& sinks,
                   const StopFlag& stop);

}  // namespace dynavins::pipeline
