#include "pipeline/lcm_publisher.hpp"

#include <stdexcept>
#include <type_traits>

#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <dynavins_lcm/status_t.hpp>

#include "pipeline/clock.hpp"
#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"

namespace dynavins::pipeline {
namespace {

constexpr int64_t kPeriodNs = 1'000'000'000;  // stats and status once a second

int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

dynavins_lcm::status_t to_lcm(const StatusUpdate& s) {
  dynavins_lcm::status_t m;
  m.utime = ns_to_utime(s.t_ns);
  m.status = static_cast<int8_t>(s.status);
  m.reason = s.reason;
  m.frames = s.frames;
  m.resets = s.resets;
  return m;
}

}  // namespace

PublisherChannels::PublisherChannels()
    : pose_imu(channels::kPoseImuRate),
      pose(channels::kPose),
      pose_corrected(channels::kPoseCorrected),
      features(channels::kFeatures),
      status(channels::kStatus),
      stats(channels::kStats),
      loops(channels::kLoops),
      path(channels::kPath) {}

std::vector<std::pair<std::string, std::string>> PublisherChannels::list() const {
  return {{"pose_imu", pose_imu}, {"pose", pose},     {"pose_corrected", pose_corrected}, {"features", features},
          {"status", status},     {"stats", stats},   {"loops", loops},                   {"path", path}};
}

void PublisherChannels::set(const std::string& assignment) {
  const auto eq = assignment.find('=');
  const std::string key = assignment.substr(0, eq);
  const std::string name = eq == std::string::npos ? "" : assignment.substr(eq + 1);
  std::string keys;
  for (const auto& [k, v] : list()) keys += (keys.empty() ? "" : ", ") + k;
  if (eq == std::string::npos || name.empty())
    throw std::invalid_argument("channel override '" + assignment + "': expected key=NAME (keys: " + keys + ")");
  std::string* target = nullptr;
  for (auto [k, field] : {std::pair{"pose_imu", &pose_imu}, {"pose", &pose}, {"pose_corrected", &pose_corrected},
                          {"features", &features}, {"status", &status}, {"stats", &stats}, {"loops", &loops},
                          {"path", &path}})
    if (key == k) target = field;
  if (!target) throw std::invalid_argument("unknown output channel key '" + key + "' (keys: " + keys + ")");
  *target = name;
}

LcmPublisher::LcmPublisher(const std::string& url, PublisherChannels channels, StatsSnapshot snapshot)
    : owned_(std::make_unique<lcm::LCM>(url)), channels_(std::move(channels)), snapshot_(std::move(snapshot)) {
  if (!owned_->good()) throw std::runtime_error("LCM cannot open '" + url + "' (check the URL and the network)");
  lcm_ = owned_.get();
  stats_.url = url;
  next_periodic_ns_ = steady_now_ns() + kPeriodNs;
}

LcmPublisher::LcmPublisher(lcm::LCM& lcm, PublisherChannels channels, StatsSnapshot snapshot)
    : lcm_(&lcm), channels_(std::move(channels)), snapshot_(std::move(snapshot)) {
  next_periodic_ns_ = steady_now_ns() + kPeriodNs;
}

LcmPublisher::~LcmPublisher() = default;

template <typename Msg>
void LcmPublisher::send(const std::string& channel, const Msg& msg, int64_t& counter) {
  if (lcm_->publish(channel, &msg) == 0) {
    ++counter;
  } else if (++stats_.failed == 1) {
    spdlog::warn("LCM publish on {} failed (further failures are only counted)", channel);
  }
}

void LcmPublisher::process(PublishItem item) {
  std::visit(
      [&](auto&& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, PoseEstimate>) {
          const bool imu = x.source == PoseSource::ImuRate;
          if (x.source == PoseSource::LoopCorrected) {
            send(channels_.pose_corrected, to_lcm(x), stats_.corrected_poses);
            return;
          }
          send(imu ? channels_.pose_imu : channels_.pose, to_lcm(x), imu ? stats_.imu_poses : stats_.window_poses);
          if (item.origin_ns > 0) (imu ? imu_latency_ : window_latency_).record(steady_now_ns() - item.origin_ns);
          if (!first_t_ns_) first_t_ns_ = x.state.t_ns;
          last_t_ns_ = x.state.t_ns;
        } else if constexpr (std::is_same_v<T, WeightedFeatureSet>) {
          send(channels_.features, to_lcm(x), stats_.feature_sets);
        } else if constexpr (std::is_same_v<T, PathUpdate>) {
          send(channels_.path, to_lcm(x), stats_.paths);
        } else if constexpr (std::is_same_v<T, HypothesesUpdate>) {
          send(channels_.loops, to_lcm(x), stats_.hypotheses);
        } else {
          // A change (new status or an event) goes out at once; otherwise the status is only
          // refreshed, and publish_periodic() sends it with the reason of the change that led to it.
          const bool change = !last_status_ || x.status != last_status_->status || !x.reason.empty();
          if (!change) x.reason = last_status_->reason;
          last_status_ = x;
          if (change) publish_status();
        }
      },
      item.payload);
  const int64_t now = steady_now_ns();
  if (now >= next_periodic_ns_) publish_periodic(now);
}

void LcmPublisher::publish_status() {
  if (last_status_) send(channels_.status, to_lcm(*last_status_), stats_.status);
}

void LcmPublisher::publish_periodic(int64_t now_ns) {
  next_periodic_ns_ = now_ns + kPeriodNs;
  if (snapshot_) {
    const double sensor_s = first_t_ns_ ? static_cast<double>(last_t_ns_ - *first_t_ns_) / 1e9 : 0.0;
    send(channels_.stats, to_lcm(snapshot_(), wall_utime(), sensor_s), stats_.stats);
  }
  publish_status();
}

void LcmPublisher::finish() { publish_periodic(steady_now_ns()); }

PublisherStats LcmPublisher::stats() const {
  PublisherStats s = stats_;
  s.imu_pose_latency = imu_latency_.summary();
  s.window_pose_latency = window_latency_.summary();
  s.imu_pose_latency_p99_ms = imu_latency_.percentile_ms(0.99);
  s.window_pose_latency_p99_ms = window_latency_.percentile_ms(0.99);
  return s;
}

}  // namespace dynavins::pipeline
