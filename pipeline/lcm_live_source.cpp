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

namespace dynavins::pipeline {
namespace {

constexpr int kPollMs = 20;

/// Decodes `rbuf` as Msg; an empty message and `why` set when it is not one.
template <typename Msg>
bool decode(const lcm::ReceiveBuffer* rbuf, Msg& msg, bool& wrong_type) {
  int64_t hash = 0;
  if (rbuf->data_size >= 8) {
    const auto* b = static_cast<const uint8_t*>(rbuf->data);
    for (int i = 0; i < 8; ++i) hash = (hash << 8) | b[i];
  }
  wrong_type = rbuf->data_size >= 8 && hash != Msg::getHash();
  if (wrong_type) return false;
  return msg.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) == static_cast<int>(rbuf->data_size);
}

}  // namespace

LiveSourceOptions::LiveSourceOptions()
    : stereo_channel(channels::kStereo), imu_channel(channels::kImu), ground_truth_channel(channels::kGroundTruth) {}

LcmLiveSource::LcmLiveSource(LiveSourceOptions options, const std::atomic<bool>* stop)
    : opt_(std::move(options)), stop_(stop), lcm_(std::make_unique<lcm::LCM>(opt_.url)) {
  if (!lcm_->good()) throw std::runtime_error("LCM cannot open '" + opt_.url + "' (check the URL and the network)");
  lcm_->subscribe(opt_.stereo_channel, &LcmLiveSource::onStereo, this);
  lcm_->subscribe(opt_.imu_channel, &LcmLiveSource::onImu, this);
  if (!opt_.ground_truth_channel.empty())
    lcm_->subscribe(opt_.ground_truth_channel, &LcmLiveSource::onGroundTruth, this);
}

LcmLiveSource::~LcmLiveSource() = default;

std::string LcmLiveSource::describe() const {
  return "live LCM " + opt_.url + " (" + opt_.stereo_channel + ", " + opt_.imu_channel + ")";
}

bool LcmLiveSource::stopRequested() const {
  return interrupt_requested() || (stop_ && stop_->load(std::memory_order_relaxed));
}

void LcmLiveSource::reject(int64_t& counter, const std::string& channel, const std::string& why) {
  if (counter++ == 0) spdlog::warn("live: {} on {} (rejected; further ones are counted)", why, channel);
}

void LcmLiveSource::onStereo(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
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
  if (f.t_ns <= last_frame_ns_ || f.t_ns <= released_ns_)
    return reject(stats_.time_went_back, channel, "a frame not after the previous one");
  last_frame_ns_ = f.t_ns;
  frames_.push_back(Held{std::move(f), steady_now_ns()});
}

void LcmLiveSource::onImu(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
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
  if (s.t_ns <= last_imu_ns_ || s.t_ns < released_ns_)
    return reject(stats_.time_went_back, channel, "an IMU sample not after the previous one");
  last_imu_ns_ = s.t_ns;
  releaseFrames(s.t_ns, false);
  ready_.push_back(s);
  released_ns_ = s.t_ns;
  ++stats_.imu;
}

void LcmLiveSource::onGroundTruth(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
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

// Frames up to `up_to_ns` go on (their IMU has arrived); with `timed_out`, so do frames that waited too long.
void LcmLiveSource::releaseFrames(int64_t up_to_ns, bool timed_out) {
  const int64_t hold_ns = static_cast<int64_t>(opt_.frame_hold_s * 1e9);
  const int64_t now = steady_now_ns();
  while (!frames_.empty()) {
    Held& h = frames_.front();
    const bool covered = event_time_ns(h.event) <= up_to_ns;
    if (!covered && !(timed_out && now - h.arrived_ns >= hold_ns)) break;
    if (!covered) ++stats_.frames_without_imu;
    released_ns_ = std::max(released_ns_, event_time_ns(h.event));
    ready_.push_back(std::move(h.event));
    frames_.pop_front();
    ++stats_.frames;
  }
}

bool LcmLiveSource::next(SensorEvent& out) {
  while (ready_.empty()) {
    if (stopRequested()) return false;
    if (lcm_->handleTimeout(kPollMs) < 0) throw std::runtime_error("LCM receive failed on " + opt_.url);
    releaseFrames(last_imu_ns_, true);
  }
  out = std::move(ready_.front());
  ready_.pop_front();
  return true;
}

}  // namespace dynavins::pipeline
