#pragma once
// The publisher stage (DESIGN.md §2): the other stages hand it their outputs through one bounded fan-in
// queue that drops rather than waits (a slow network never stalls the estimator), and it publishes them
// on LCM: IMU-rate pose, window pose, weighted features, the estimator's status (on change and once a
// second) and the pipeline's stats (once a second). It also measures how long each pose took from its
// input's arrival to being published.
//
// The LCM instance is the only thing here that knows of the network; the stage itself is a plain object
// with process()/finish(), run on its own thread by pipeline/vio (or called directly in tests).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/publish_item.hpp"
#include "pipeline/latency_histogram.hpp"
#include "pipeline/pipeline.hpp"

namespace lcm {
class LCM;
}

namespace dynavins::pipeline {

/// Output channel names; the defaults are pipeline/lcm_channels.hpp's.
struct PublisherChannels {
  std::string pose_imu, pose, pose_corrected, features, status, stats, loops, path;
  PublisherChannels();
  /// Sets one name from "key=NAME" (a key of list()). Throws
  /// std::invalid_argument naming the key and listing the valid ones.
  void set(const std::string& assignment);
  /// (key, channel) for every output, in a fixed order (logs, README).
  std::vector<std::pair<std::string, std::string>> list() const;
};

/// What the publisher sent, for the run summary.
struct PublisherStats {
  std::string url;
  int64_t imu_poses = 0, window_poses = 0, corrected_poses = 0, feature_sets = 0, status = 0, stats = 0;
  int64_t paths = 0, hypotheses = 0;
  int64_t failed = 0;  ///< lcm publish calls that returned an error
  /// Input arrival -> published, per pose kind (steady clock; the queue wait before the first stage is
  /// in that stage's wait statistics).
  LatencySummary imu_pose_latency, window_pose_latency;
  double imu_pose_latency_p99_ms = 0, window_pose_latency_p99_ms = 0;
};

class LcmPublisher {
 public:
  /// Snapshot of the running pipeline for the stats message (stages, queues, wall time); may be empty.
  using StatsSnapshot = std::function<RunReport()>;

  /// Publishes on a new LCM instance for `url`; throws std::runtime_error naming the URL if LCM cannot
  /// open it.
  LcmPublisher(const std::string& url, PublisherChannels channels, StatsSnapshot snapshot = {});
  /// Publishes on the caller's instance (tests on memq://, where only the same instance receives).
  LcmPublisher(lcm::LCM& lcm, PublisherChannels channels, StatsSnapshot snapshot = {});
  ~LcmPublisher();
  LcmPublisher(const LcmPublisher&) = delete;
  LcmPublisher& operator=(const LcmPublisher&) = delete;

  /// Publishes one item; sends stats and status when a second has passed since the last time.
  void process(PublishItem item);
  /// End of the run: the last stats and status.
  void finish();

  /// Counters and latencies; read after the publisher's thread has ended.
  PublisherStats stats() const;

 private:
  void publish_periodic(int64_t now_ns);
  void publish_status();
  template <typename Msg>
  void send(const std::string& channel, const Msg& msg, int64_t& counter);

  std::unique_ptr<lcm::LCM> owned_;
  lcm::LCM* lcm_ = nullptr;
  PublisherChannels channels_;
  StatsSnapshot snapshot_;
  PublisherStats stats_;
  LatencyHistogram imu_latency_, window_latency_;
  std::optional<StatusUpdate> last_status_;
  int64_t next_periodic_ns_ = 0;
  std::optional<int64_t> first_t_ns_;
  int64_t last_t_ns_ = 0;
};

}  // namespace dynavins::pipeline
