#pragma once
// The live input of `dynavins live` (DESIGN.md §2): a SensorSource that subscribes to the stereo-image and
// IMU channels (and, when present, ground truth) and hands their messages on in time order, so the run
// that follows is the same as a replay's.
//
// Order: each channel's messages go on as they arrive, so the IMU-rate pose is never held back; only
// within a channel must time increase. Across channels no order is needed: a camera frame usually
// arrives after the IMU samples past its time (image transfer), and the IMU stage cuts its interval from
// the samples it keeps (ImuIntervalBuilder takes any interleaving).
// Bad messages never reach the pipeline; each is counted by reason and the first of each kind is logged:
// another type on the channel (fingerprint), a truncated or undecodable payload, an image whose size does
// not match its width and height or the calibration, non-finite IMU values, and times that go back.
// next() blocks on the network and returns false once SIGINT arrived or `stop` is set.

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "io/sensor_source.hpp"

namespace lcm {
class LCM;
class ReceiveBuffer;
class Subscription;
}  // namespace lcm

namespace dynavins::pipeline {

struct LiveSourceOptions {
  std::string url;
  std::string stereo_channel;  ///< stereo_image_t (default channels::kStereo)
  std::string imu_channel;     ///< imu_t (default channels::kImu)
  std::string ground_truth_channel;  ///< ground_truth_t (default channels::kGroundTruth); empty: not read
  int image_width = 0, image_height = 0;  ///< the calibration's; 0 = not checked
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
  int64_t rejected() const { return wrong_type + undecodable + bad_image + bad_imu + time_went_back; }
};

class LcmLiveSource final : public io::SensorSource {
 public:
  /// Subscribes; throws std::runtime_error naming the URL if LCM cannot open it.
  explicit LcmLiveSource(LiveSourceOptions options, const std::atomic<bool>* stop = nullptr);
  /// Subscribes on the caller's instance (tests on memq://, where only the same instance receives).
  LcmLiveSource(lcm::LCM& lcm, LiveSourceOptions options, const std::atomic<bool>* stop = nullptr);
  ~LcmLiveSource() override;

  bool next(SensorEvent& out) override;
  double progress() const override { return 0.0; }
  std::string describe() const override;
  /// Read after the run (the replay thread writes it).
  const LiveSourceStats& stats() const { return stats_; }

 private:
  void on_stereo(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_imu(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_ground_truth(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void reject(int64_t& counter, const std::string& channel, const std::string& why);
  bool stop_requested() const;

  LiveSourceOptions opt_;
  const std::atomic<bool>* stop_;
  void subscribe();

  std::unique_ptr<lcm::LCM> owned_;
  lcm::LCM* lcm_ = nullptr;
  std::vector<lcm::Subscription*> subscriptions_;  // removed again in the destructor (a caller's instance)
  std::deque<SensorEvent> ready_;  // received, not yet handed on (arrival order)
  int64_t last_frame_ns_ = INT64_MIN, last_imu_ns_ = INT64_MIN, last_gt_ns_ = INT64_MIN;
  LiveSourceStats stats_;
};

}  // namespace dynavins::pipeline
