#pragma once
// The live input of `dynavins live` (DESIGN.md §2): a SensorSource that subscribes to the stereo-image and
// IMU channels (and, when present, ground truth) and hands their messages on in time order, so the run
// that follows is the same as a replay's.
//
// Order: LCM delivers the channels as they arrive, and a frame may come in before the IMU samples that
// reach its time. A frame is therefore held until an IMU sample at or after its time has arrived (or
// `frame_hold_s` of wall time passed), and everything is released in time order.
// Bad messages never reach the pipeline; each is counted by reason and the first of each kind is logged:
// another type on the channel (fingerprint), a truncated or undecodable payload, an image whose size does
// not match its width and height or the calibration, non-finite IMU values, and times that go back.
// next() blocks on the network and returns false once SIGINT arrived or `stop` is set.

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include "io/sensor_source.hpp"

namespace lcm {
class LCM;
class ReceiveBuffer;
}  // namespace lcm

namespace dynavins::pipeline {

struct LiveSourceOptions {
  std::string url;
  std::string stereo_channel;  ///< stereo_image_t (default channels::kStereo)
  std::string imu_channel;     ///< imu_t (default channels::kImu)
  std::string ground_truth_channel;  ///< ground_truth_t (default channels::kGroundTruth); empty: not read
  int image_width = 0, image_height = 0;  ///< the calibration's; 0 = not checked
  double frame_hold_s = 0.2;              ///< wall time a frame waits for its IMU before it goes on anyway
  LiveSourceOptions();
};

/// What arrived, and what was rejected and why (for the run summary).
struct LiveSourceStats {
  int64_t frames = 0, imu = 0, ground_truth = 0;  ///< handed on
  int64_t wrong_type = 0;       ///< payload of another LCM type (fingerprint)
  int64_t undecodable = 0;      ///< truncated or corrupt payload
  int64_t bad_image = 0;        ///< image size not matching its width/height, or the calibration's
  int64_t bad_imu = 0;          ///< NaN or Inf in an IMU sample
  int64_t time_went_back = 0;   ///< a message not after the previous one on its channel
  int64_t frames_without_imu = 0;  ///< frames released after frame_hold_s without an IMU sample past them
  int64_t rejected() const { return wrong_type + undecodable + bad_image + bad_imu + time_went_back; }
};

class LcmLiveSource final : public io::SensorSource {
 public:
  /// Subscribes; throws std::runtime_error naming the URL if LCM cannot open it.
  explicit LcmLiveSource(LiveSourceOptions options, const std::atomic<bool>* stop = nullptr);
  ~LcmLiveSource() override;

  bool next(SensorEvent& out) override;
  double progress() const override { return 0.0; }
  std::string describe() const override;
  /// Read after the run (the replay thread writes it).
  const LiveSourceStats& stats() const { return stats_; }

 private:
  void onStereo(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void onImu(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void onGroundTruth(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void reject(int64_t& counter, const std::string& channel, const std::string& why);
  void releaseFrames(int64_t up_to_ns, bool timed_out);
  bool stopRequested() const;

  LiveSourceOptions opt_;
  const std::atomic<bool>* stop_;
  std::unique_ptr<lcm::LCM> lcm_;
  struct Held {
    SensorEvent event;
    int64_t arrived_ns = 0;  // steady clock
  };
  std::deque<Held> frames_;        // frames waiting for their IMU, in time order
  std::deque<SensorEvent> ready_;  // in time order
  int64_t last_frame_ns_ = INT64_MIN, last_imu_ns_ = INT64_MIN, last_gt_ns_ = INT64_MIN;
  int64_t released_ns_ = INT64_MIN;  // newest time handed to ready_
  LiveSourceStats stats_;
};

}  // namespace dynavins::pipeline
