#pragma once
// Sensor events in LCM event logs: the project's recorded-sensor-log format (DESIGN.md §3).
//  - write_sensor_event(): one event to its channel (CAM_STEREO, IMU, GROUND_TRUTH; a simulated
//    frame's label image goes to SIM_LABELS just before its frame).
//  - LcmLogSource: a log as a time-ordered io::SensorSource. Events on unknown channels are
//    skipped and counted (a log recorded live may carry anything); per channel, timestamps must
//    strictly increase. Small disorder between channels (live recording) is undone by a bounded
//    reorder window.

#include <map>
#include <memory>
#include <queue>
#include <string>
#include <vector>

#include "io/sensor_source.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_log.hpp"

namespace dynavins::pipeline {

/// Appends one sensor event to `log` on its channel.
void write_sensor_event(LcmLogWriter& log, const SensorEvent& event, ImageEncoding encoding);

class LcmLogSource final : public io::SensorSource {
 public:
  /// `reorder_window_ns`: how far (in sensor time) an event may arrive late on its channel
  /// relative to other channels and still be delivered in order.
  explicit LcmLogSource(const std::string& path, int64_t reorder_window_ns = 200'000'000);
  bool next(SensorEvent& out) override;
  double progress() const override;
  std::string describe() const override;
  /// Events on channels that carry no sensor data, by channel.
  const std::map<std::string, int64_t>& skipped() const { return skipped_; }

 private:
  struct Pending {
    int64_t t_ns;
    int64_t order;  // read order breaks time ties, so equal stamps keep their log order
    std::shared_ptr<SensorEvent> event;
    bool operator>(const Pending& o) const { return t_ns != o.t_ns ? t_ns > o.t_ns : order > o.order; }
  };
  /// Reads log events until one sensor event is queued; false at the end of the log.
  bool read_one();

  LcmLogReader reader_;
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> pending_;
  std::map<std::string, int64_t> last_time_;  // per channel, for the monotonic check
  std::map<int64_t, cv::Mat> labels_;         // SIM_LABELS waiting for their frame, by utime
  std::map<std::string, int64_t> skipped_;
  int64_t newest_ns_ = INT64_MIN / 2;  // "nothing read yet", far enough from the limit to subtract from
  int64_t order_ = 0;
  int64_t reorder_window_ns_;
  bool eof_ = false;
  bool skips_reported_ = false;
};

}  // namespace dynavins::pipeline
