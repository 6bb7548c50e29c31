#include "pipeline/lcm_live_source.hpp"

#include <climits>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <dynavins_lcm/ground_truth_t.hpp>
#include <dynavins_lcm/imu_t.hpp>
#include <dynavins_lcm/stereo_image_t.hpp>

#include "pipeline/clock.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/wire_decode.hpp"

namespace dynavins::pipeline {
namespace {

constexpr int kPollMs = 20;

/// Decodes `rbuf` as Msg: false when it is not one, with `wrong_type` set when its fingerprint is another
/// type's (rather than a truncated or corrupt payload).
template <typename Msg>
bool decode(const lcm::ReceiveBuffer* rbuf, Msg& msg, bool& wrong_type) {
  std::string problem;
  return try_decode_payload(static_cast<const uint8_t*>(rbuf->data), rbuf->data_size, msg, problem, wrong_type);
}

}  // namespace

LiveSourceOptions::LiveSourceOptions()
    : stereo_channel(channels::kStereo), imu_channel(channels::kImu), ground_truth_channel(channels::kGroundTruth) {}

LcmLiveSource::LcmLiveSource(LiveSourceOptions options, const std::atomic<bool>* stop)
    : opt_(std::move(options)), stop_(stop), owned_(std::make_unique<lcm::LCM>(opt_.url)), lcm_(owned_.get()) {
  if (!lcm_->good()) throw std::runtime_error("LCM cannot open '" + opt_.url + "' (check the URL and the network)");
  subscribe();
}

LcmLiveSource::LcmLiveSource(lcm::LCM& lcm, LiveSourceOptions options, const std::atomic<bool>* stop)
    : opt_(std::move(options)), stop_(stop), lcm_(&lcm) {
  subscribe();
}

void LcmLiveSource::subscribe() {
  subscriptions_.push_back(lcm_->subscribe(opt_.stereo_channel, &LcmLiveSource::on_stereo, this));
  subscriptions_.push_back(lcm_->subscribe(opt_.imu_channel, &LcmLiveSource::on_imu, this));
  if (!opt_.ground_truth_channel.empty())
    subscriptions_.push_back(lcm_->subscribe(opt_.ground_truth_channel, &LcmLiveSource::on_ground_truth, this));
}

LcmLiveSource::~LcmLiveSource() {
  for (lcm::Subscription* sub : subscriptions_) lcm_->unsubscribe(sub);
}

std::string LcmLiveSource::describe() const {
  return "live LCM " + opt_.url + " (" + opt_.stereo_channel + ", " + opt_.imu_channel + ")";
}

bool LcmLiveSource::stop_requested() const {
  return interrupt_requested() || (stop_ && stop_->load(std::memory_order_relaxed));
}

void LcmLiveSource::reject(int64_t& counter, const std::string& channel, const std::string& why) {
  if (counter++ == 0) spdlog::warn("live: {} on {} (rejected; further ones are counted)", why, channel);
}

void LcmLiveSource::on_stereo(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  dynavins_lcm::stereo_image_t msg;
  bool wrong_type = false;
  if (!decode(rbuf, msg, wrong_type))
    return reject(wrong_type ? stats_.wrong_type : stats_.undecodable, channel,
                  wrong_type ? "a message of another type" : "a truncated or corrupt stereo_image_t");
  StereoFrame f;
  try {
    f = from_lcm(msg);
  } catch (const std::exception& e) {
    return reject(stats_.bad_image, channel, e.what());
  }
  if (opt_.image_width > 0 && (f.left.cols != opt_.image_width || f.left.rows != opt_.image_height))
    return reject(stats_.bad_image, channel,
                  "an image of " + std::to_string(f.left.cols) + "x" + std::to_string(f.left.rows) +
                      " where the calibration says " + std::to_string(opt_.image_width) + "x" +
                      std::to_string(opt_.image_height));
  if (f.t_ns <= last_frame_ns_) return reject(stats_.time_went_back, channel, "a frame not after the previous one");
  last_frame_ns_ = f.t_ns;
  ready_.push_back(std::move(f));
  ++stats_.frames;
}

void LcmLiveSource::on_imu(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  dynavins_lcm::imu_t msg;
  bool wrong_type = false;
  if (!decode(rbuf, msg, wrong_type))
    return reject(wrong_type ? stats_.wrong_type : stats_.undecodable, channel,
                  wrong_type ? "a message of another type" : "a truncated or corrupt imu_t");
  ImuSample s;
  try {
    s = from_lcm(msg);
  } catch (const std::exception& e) {
    return reject(stats_.bad_imu, channel, e.what());
  }
  if (s.t_ns <= last_imu_ns_) return reject(stats_.time_went_back, channel, "an IMU sample not after the previous one");
  last_imu_ns_ = s.t_ns;
  ready_.push_back(s);
  ++stats_.imu;
}

void LcmLiveSource::on_ground_truth(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  dynavins_lcm::ground_truth_t msg;
  bool wrong_type = false;
  if (!decode(rbuf, msg, wrong_type))
    return reject(wrong_type ? stats_.wrong_type : stats_.undecodable, channel,
                  wrong_type ? "a message of another type" : "a truncated or corrupt ground_truth_t");
  GroundTruthState g;
  try {
    g = from_lcm(msg);
  } catch (const std::exception& e) {
    return reject(stats_.undecodable, channel, e.what());
  }
  if (g.t_ns <= last_gt_ns_) return reject(stats_.time_went_back, channel, "a ground-truth state not after the previous one");
  last_gt_ns_ = g.t_ns;
  // Ground truth is for evaluation only: it does not wait for anything, and never holds the sensors back.
  ready_.push_back(std::move(g));
  ++stats_.ground_truth;
}

bool LcmLiveSource::next(SensorEvent& out) {
  while (ready_.empty()) {
    if (stop_requested()) return false;
    if (lcm_->handleTimeout(kPollMs) < 0) throw std::runtime_error("LCM receive failed on " + opt_.url);
  }
  out = std::move(ready_.front());
  ready_.pop_front();
  return true;
}

}  // namespace dynavins::pipeline
