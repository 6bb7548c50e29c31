#include "io/rosbag/rosbag_reader.hpp"

#include "io/input_error.hpp"
#include "io/rosbag/bag_structure_check.hpp"

#include <cmath>
#include <cstring>
#include <deque>
#include <exception>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/query.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <opencv2/imgproc.hpp>
#include <spdlog/fmt/fmt.h>
#include <spdlog/spdlog.h>

namespace dynavins::io {

namespace {

enum Stream : int { kLeft = 0, kRight = 1, kImu = 2, kOdometry = 3, kStreamCount = 4 };

const char* stream_name(int s) {
  static const char* names[] = {"left image", "right image", "IMU", "odometry"};
  return names[s];
}

template <typename Msg>
std::string type_of() {
  return ros::message_traits::DataType<Msg>::value();
}

template <typename Msg>
std::string md5_of() {
  return ros::message_traits::MD5Sum<Msg>::value();
}

struct PendingImage {
  int64_t t_ns = 0;
  cv::Mat gray;
};

bool finite3(double x, double y, double z) { return std::isfinite(x) && std::isfinite(y) && std::isfinite(z); }

}  // namespace

std::string RosbagReadStats::summary() const {
  return fmt::format(
      "{} stereo frames ({} left, {} right images; {} left and {} right unmatched), {} IMU samples, "
      "{} ground-truth states, {} messages skipped for bad stamps",
      stereo_frames, left_images, right_images, unmatched_left, unmatched_right, imu_samples, ground_truth_states,
      skipped_bad_stamps);
}

struct RosbagReader::Impl {
  std::string path;
  RosbagReaderOptions opt;
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  rosbag::View::iterator end;
  bool started = false;
  bool finished = false;
  std::exception_ptr failure;  // set once a read has thrown: the reader's position is then unknown
  int64_t consumed = 0;        // messages of the view read so far, for progress()
  int64_t total = 0;           // messages of the view
  std::string last_source;     // topic and index of the message that completed the last event
  // Sensor-time order for next(): events keyed by (t_ns, arrival) until none older can come.
  std::map<std::pair<int64_t, int64_t>, SensorEvent> reorder;
  int64_t arrivals = 0;
  int64_t newest_ns = std::numeric_limits<int64_t>::min() / 2;
  bool bag_done = false;
  std::vector<RosbagTopicInfo> topics;
  std::map<std::string, int> stream_of_topic;
  std::string topic_of[kStreamCount];
  int64_t index[kStreamCount] = {0, 0, 0, 0};  // messages seen per stream, skipped ones included
  std::optional<int64_t> last_stamp[kStreamCount];
  std::deque<PendingImage> pending[2];  // per side, waiting for the other side's image
  RosbagReadStats stats;

  // "topic T message #i" for errors about one message.
  std::string where(int s, int64_t i) const { return fmt::format("topic {} message #{}", topic_of[s], i); }
  [[noreturn]] void fail(const std::string& problem) const { throw InputError(path, 0, problem); }

  void open();
  template <typename Msg>
  void check_topic(int s);
  // Runs one library call, turning its exceptions into an InputError naming the file.
  template <typename F>
  auto guarded(const char* what, F&& f) -> decltype(f());

  std::optional<SensorEvent> next_in_bag_order();
  std::optional<SensorEvent> handle(const rosbag::MessageInstance& m);
  template <typename Msg>
  std::unique_ptr<Msg> decode(const rosbag::MessageInstance& m, int s, int64_t i);
  bool accept_stamp(int s, int64_t i, const std_msgs::Header& h, int64_t* t_ns);
  cv::Mat to_gray(int s, int64_t i, const sensor_msgs::Image& img) const;
  std::optional<SensorEvent> on_image(int side, int64_t t_ns, cv::Mat gray);
  ImuSample to_imu(int64_t i, int64_t t_ns, const sensor_msgs::Imu& msg) const;
  GroundTruthState to_ground_truth(int64_t i, int64_t t_ns, const nav_msgs::Odometry& msg) const;
  void finish();
};

template <typename F>
auto RosbagReader::Impl::guarded(const char* what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    fail(fmt::format("corrupt or truncated ROS bag ({}): {}", what, e.what()));
  }
}

void RosbagReader::Impl::open() {
  if (opt.left_topic.empty()) fail("no left image topic configured");
  if (opt.stereo_tolerance_ns < 0) fail("stereo_tolerance_ns must be >= 0");
  if (opt.max_pending_images == 0) fail("max_pending_images must be >= 1");
  if (opt.reorder_window_ns < 0) fail("reorder_window_ns must be >= 0");
  topic_of[kLeft] = opt.left_topic;
  topic_of[kRight] = opt.right_topic;
  topic_of[kImu] = opt.imu_topic;
  topic_of[kOdometry] = opt.odometry_topic;
  for (int s = 0; s < kStreamCount; ++s) {
    if (topic_of[s].empty()) continue;
    if (!stream_of_topic.emplace(topic_of[s], s).second)
      fail(fmt::format("topic {} configured for both the {} and the {} stream", topic_of[s],
                       stream_name(stream_of_topic[topic_of[s]]), stream_name(s)));
  }

  // rosbag_storage crashes on some corrupt files instead of throwing; this throws first.
  const detail::BagStructure structure = detail::check_bag_structure(path);
  spdlog::debug("{}: {} connections, {} chunks, {} index entries", path, structure.connections, structure.chunks,
                structure.index_entries);
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    fail(fmt::format("cannot open as a ROS 1 bag (missing, truncated or corrupt): {}", e.what()));
  }

  guarded("reading the index", [&] {
    rosbag::View all(bag);
    std::map<std::string, RosbagTopicInfo> by_topic;
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      RosbagTopicInfo& t = by_topic[c->topic];
      t.topic = c->topic;
      // Several connections may share a topic; a differing type is reported by check_topic.
      if (t.datatype.empty()) t.datatype = c->datatype;
    }
    for (auto& [name, info] : by_topic) {
      rosbag::View one(bag, rosbag::TopicQuery(name));
      info.messages = one.size();
      topics.push_back(info);
    }
    return 0;
  });

  check_topic<sensor_msgs::Image>(kLeft);
  check_topic<sensor_msgs::Image>(kRight);
  check_topic<sensor_msgs::Imu>(kImu);
  check_topic<nav_msgs::Odometry>(kOdometry);

  std::vector<std::string> wanted;
  for (const auto& [name, s] : stream_of_topic) wanted.push_back(name);
  view = guarded("reading the index", [&] { return std::make_unique<rosbag::View>(bag, rosbag::TopicQuery(wanted)); });
  total = guarded("reading the index", [&] { return static_cast<int64_t>(view->size()); });
}

template <typename Msg>
void RosbagReader::Impl::check_topic(int s) {
  const std::string& name = topic_of[s];
  if (name.empty()) return;
  const std::string expected = type_of<Msg>();
  bool found = false;
  guarded("reading the index", [&] {
    rosbag::View one(bag, rosbag::TopicQuery(name));
    for (const rosbag::ConnectionInfo* c : one.getConnections()) {
      found = true;
      if (c->datatype != expected)
        fail(fmt::format("topic {} ({} stream) has type {}, expected {}", name, stream_name(s), c->datatype, expected));
      // Same name, other definition: the bytes would not have this build's layout.
      if (c->md5sum != "*" && c->md5sum != md5_of<Msg>())
        fail(fmt::format("topic {} has type {} with MD5 {}, this build reads MD5 {}", name, c->datatype, c->md5sum,
                         md5_of<Msg>()));
    }
    return 0;
  });
  if (!found) {
    std::string have;
    for (const auto& t : topics) have += fmt::format("{}{} [{}]", have.empty() ? "" : ", ", t.topic, t.datatype);
    fail(fmt::format("topic {} ({} stream, {}) not in the bag; it has: {}", name, stream_name(s), expected,
                     have.empty() ? "no topics" : have));
  }
}

bool RosbagReader::Impl::accept_stamp(int s, int64_t i, const std_msgs::Header& h, int64_t* t_ns) {
  if (h.stamp.nsec >= 1'000'000'000u)
    fail(fmt::format("{}: header stamp nsec {} out of range", where(s, i), h.stamp.nsec));
  const int64_t t = static_cast<int64_t>(h.stamp.sec) * 1'000'000'000 + static_cast<int64_t>(h.stamp.nsec);
  if (last_stamp[s] && t <= *last_stamp[s]) {
    const std::string what = fmt::format("{}: header stamp {} ns is {} the previous one ({} ns)", where(s, i), t,
                                         t == *last_stamp[s] ? "a duplicate of" : "before", *last_stamp[s]);
    if (opt.bad_stamp == BadStampPolicy::Throw) fail(what);
    ++stats.skipped_bad_stamps;
    // Logged per message up to a point, then only counted; the end-of-bag summary has the total.
    if (stats.skipped_bad_stamps <= 20) spdlog::warn("{}: {} (skipped)", path, what);
    if (stats.skipped_bad_stamps == 20) spdlog::warn("{}: further skipped messages only counted", path);
    return false;
  }
  last_stamp[s] = t;
  *t_ns = t;
  return true;
}

cv::Mat RosbagReader::Impl::to_gray(int s, int64_t i, const sensor_msgs::Image& img) const {
  int channels = 0;
  int code = -1;
  const std::string& enc = img.encoding;
  if (enc == "mono8") {
    channels = 1;
  } else if (enc == "bgr8") {
    channels = 3, code = cv::COLOR_BGR2GRAY;
  } else if (enc == "rgb8") {
    channels = 3, code = cv::COLOR_RGB2GRAY;
  } else if (enc == "bgra8") {
    channels = 4, code = cv::COLOR_BGRA2GRAY;
  } else if (enc == "rgba8") {
    channels = 4, code = cv::COLOR_RGBA2GRAY;
  } else {
    fail(fmt::format("{}: unsupported image encoding '{}' (supported: mono8, bgr8, rgb8, bgra8, rgba8)", where(s, i),
                     enc));
  }
  constexpr uint64_t kMaxDim = std::numeric_limits<int>::max();
  if (img.width == 0 || img.height == 0 || img.width > kMaxDim || img.height > kMaxDim || img.step > kMaxDim)
    fail(fmt::format("{}: bad image size {}x{} (step {})", where(s, i), img.width, img.height, img.step));
  if (static_cast<uint64_t>(img.step) < static_cast<uint64_t>(img.width) * channels)
    fail(fmt::format("{}: image step {} is less than width {} x {} channels", where(s, i), img.step, img.width,
                     channels));
  const uint64_t need = static_cast<uint64_t>(img.step) * img.height;
  if (img.data.size() != need)
    fail(fmt::format("{}: image data has {} bytes, step x height = {}", where(s, i), img.data.size(), need));

  // A view of the message's buffer; the result is always a fresh copy, so the message can go.
  const cv::Mat src(static_cast<int>(img.height), static_cast<int>(img.width), CV_8UC(channels),
                    const_cast<uint8_t*>(img.data.data()), img.step);
  if (code < 0) return src.clone();
  cv::Mat gray;
  cv::cvtColor(src, gray, code);
  return gray;
}

std::optional<SensorEvent> RosbagReader::Impl::on_image(int side, int64_t t_ns, cv::Mat gray) {
  const int other_side = 1 - side;
  auto& other = pending[other_side];
  int64_t& other_unmatched = other_side == kLeft ? stats.unmatched_left : stats.unmatched_right;
  // Stamps only grow per side, so a waiting partner older than t - tolerance can never match.
  while (!other.empty() && other.front().t_ns < t_ns - opt.stereo_tolerance_ns) {
    other.pop_front();
    ++other_unmatched;
  }
  if (!other.empty() && other.front().t_ns <= t_ns + opt.stereo_tolerance_ns) {
    StereoFrame frame;
    frame.seq = stats.stereo_frames++;
    if (side == kLeft) {
      frame.t_ns = t_ns;
      frame.left = std::move(gray);
      frame.right = std::move(other.front().gray);
    } else {
      frame.t_ns = other.front().t_ns;
      frame.left = std::move(other.front().gray);
      frame.right = std::move(gray);
    }
    other.pop_front();
    return SensorEvent(std::move(frame));
  }
  auto& own = pending[side];
  own.push_back({t_ns, std::move(gray)});
  if (own.size() > opt.max_pending_images) {
    own.pop_front();
    ++(side == kLeft ? stats.unmatched_left : stats.unmatched_right);
  }
  return std::nullopt;
}

ImuSample RosbagReader::Impl::to_imu(int64_t i, int64_t t_ns, const sensor_msgs::Imu& msg) const {
  const auto& a = msg.linear_acceleration;
  const auto& w = msg.angular_velocity;
  if (!finite3(a.x, a.y, a.z) || !finite3(w.x, w.y, w.z))
    fail(fmt::format("{}: non-finite acceleration or angular velocity", where(kImu, i)));
  ImuSample out;
  out.t_ns = t_ns;
  out.acc = Eigen::Vector3d(a.x, a.y, a.z);
  out.gyr = Eigen::Vector3d(w.x, w.y, w.z);
  return out;
}

GroundTruthState RosbagReader::Impl::to_ground_truth(int64_t i, int64_t t_ns, const nav_msgs::Odometry& msg) const {
  const auto& p = msg.pose.pose.position;
  const auto& q = msg.pose.pose.orientation;
  const auto& v = msg.twist.twist.linear;
  if (!finite3(p.x, p.y, p.z) || !finite3(q.x, q.y, q.z) || !std::isfinite(q.w))
    fail(fmt::format("{}: non-finite pose", where(kOdometry, i)));
  GroundTruthState out;
  out.t_ns = t_ns;
  out.p_wb = Eigen::Vector3d(p.x, p.y, p.z);
  const Eigen::Quaterniond quat(q.w, q.x, q.y, q.z);
  // Float round-off is renormalised; anything far from unit length is not a rotation.
  if (std::abs(quat.norm() - 1.0) > 1e-2)
    fail(fmt::format("{}: orientation quaternion has norm {}, not a rotation", where(kOdometry, i), quat.norm()));
  out.q_wb = quat.normalized();

  TwistFrame frame = opt.twist_frame;
  if (frame == TwistFrame::Auto)
    frame = (!msg.child_frame_id.empty() && msg.child_frame_id != msg.header.frame_id) ? TwistFrame::Body
                                                                                       : TwistFrame::World;
  if (frame == TwistFrame::Ignore) return out;
  if (!finite3(v.x, v.y, v.z)) fail(fmt::format("{}: non-finite twist", where(kOdometry, i)));
  const Eigen::Vector3d vel(v.x, v.y, v.z);
  out.v_wb = frame == TwistFrame::Body ? Eigen::Vector3d(out.q_wb * vel) : vel;
  out.has_velocity = true;
  return out;
}

namespace {

// Steps over a serialized message's fields. roscpp sizes a string or vector by its length
// prefix before checking that the bytes are there, so a corrupt length would allocate up to
// 4 GiB; checking the prefixes against the message size first avoids that.
class RawWalker {
 public:
  explicit RawWalker(const std::vector<uint8_t>& raw) : raw_(raw) {}
  bool skip(std::size_t n) {
    if (n > raw_.size() - at_) return false;
    at_ += n;
    return true;
  }
  bool sized() {  // a string or a uint8[]: uint32 length, then the bytes
    uint32_t len = 0;
    if (raw_.size() - at_ < 4) return false;
    std::memcpy(&len, raw_.data() + at_, 4);
    at_ += 4;
    return skip(len);
  }
  bool header() { return skip(4 + 8) && sized(); }  // seq, stamp, frame_id

 private:
  const std::vector<uint8_t>& raw_;
  std::size_t at_ = 0;
};

// Field layouts (sensor_msgs/Image, sensor_msgs/Imu, nav_msgs/Odometry as of ROS 1 Noetic).
bool lengths_fit(const std::vector<uint8_t>& raw, const sensor_msgs::Image*) {
  RawWalker w(raw);
  return w.header() && w.skip(8) && w.sized() && w.skip(5) && w.sized();  // h, w; encoding; bigendian, step; data
}
bool lengths_fit(const std::vector<uint8_t>& raw, const sensor_msgs::Imu*) {
  RawWalker w(raw);
  return w.header() && w.skip(296);  // 3 x (vector or quaternion + 3x3 covariance)
}
bool lengths_fit(const std::vector<uint8_t>& raw, const nav_msgs::Odometry*) {
  RawWalker w(raw);
  return w.header() && w.sized() && w.skip(680);  // child_frame_id; pose, twist with 6x6 covariances
}

}  // namespace

template <typename Msg>
std::unique_ptr<Msg> RosbagReader::Impl::decode(const rosbag::MessageInstance& m, int s, int64_t i) {
  // The connection's type and MD5 were checked on open, so the bytes are this type's layout.
  const std::vector<uint8_t> raw = guarded("reading a message", [&] {
    std::vector<uint8_t> bytes(m.size());
    ros::serialization::OStream out(bytes.data(), static_cast<uint32_t>(bytes.size()));
    m.write(out);
    return bytes;
  });
  if (!lengths_fit(raw, static_cast<const Msg*>(nullptr)))
    fail(fmt::format("{}: malformed {} ({} bytes): a length field runs past the message", where(s, i), type_of<Msg>(),
                     raw.size()));
  auto msg = std::make_unique<Msg>();
  guarded("decoding a message", [&] {
    ros::serialization::IStream in(const_cast<uint8_t*>(raw.data()), static_cast<uint32_t>(raw.size()));
    ros::serialization::deserialize(in, *msg);
    return 0;
  });
  return msg;
}

std::optional<SensorEvent> RosbagReader::Impl::handle(const rosbag::MessageInstance& m) {
  const auto found = stream_of_topic.find(m.getTopic());
  if (found == stream_of_topic.end()) return std::nullopt;  // the view only holds our topics
  const int s = found->second;
  const int64_t i = index[s]++;
  last_source = where(s, i);
  int64_t t_ns = 0;
  switch (s) {
    case kLeft:
    case kRight: {
      const auto msg = decode<sensor_msgs::Image>(m, s, i);
      if (!accept_stamp(s, i, msg->header, &t_ns)) return std::nullopt;
      cv::Mat gray = to_gray(s, i, *msg);
      ++(s == kLeft ? stats.left_images : stats.right_images);
      if (topic_of[kRight].empty()) {  // mono
        StereoFrame frame;
        frame.t_ns = t_ns;
        frame.seq = stats.stereo_frames++;
        frame.left = std::move(gray);
        return SensorEvent(std::move(frame));
      }
      return on_image(s, t_ns, std::move(gray));
    }
    case kImu: {
      const auto msg = decode<sensor_msgs::Imu>(m, s, i);
      if (!accept_stamp(s, i, msg->header, &t_ns)) return std::nullopt;
      ImuSample sample = to_imu(i, t_ns, *msg);
      ++stats.imu_samples;
      return SensorEvent(std::move(sample));
    }
    default: {
      const auto msg = decode<nav_msgs::Odometry>(m, s, i);
      if (!accept_stamp(s, i, msg->header, &t_ns)) return std::nullopt;
      GroundTruthState gt = to_ground_truth(i, t_ns, *msg);
      ++stats.ground_truth_states;
      return SensorEvent(std::move(gt));
    }
  }
}

void RosbagReader::Impl::finish() {
  finished = true;
  // Whatever still waits for a partner at the end never gets one.
  stats.unmatched_left += static_cast<int64_t>(pending[kLeft].size());
  stats.unmatched_right += static_cast<int64_t>(pending[kRight].size());
  pending[kLeft].clear();
  pending[kRight].clear();
  spdlog::info("{}: {}", path, stats.summary());
  if (stats.unmatched_left + stats.unmatched_right > 0)
    spdlog::warn("{}: {} left and {} right images had no partner within {} ns and were dropped", path,
                 stats.unmatched_left, stats.unmatched_right, opt.stereo_tolerance_ns);
  if (stats.skipped_bad_stamps > 0)
    spdlog::warn("{}: {} messages skipped for stamps not after their predecessor", path, stats.skipped_bad_stamps);
}

std::optional<SensorEvent> RosbagReader::Impl::next_in_bag_order() {
  if (failure) std::rethrow_exception(failure);
  if (finished) return std::nullopt;
  try {
    if (!started) {
      guarded("reading the first chunk", [&] {
        it = view->begin();
        end = view->end();
        return 0;
      });
      started = true;
    }
    while (guarded("reading a chunk", [&] { return it != end; })) {
      std::optional<SensorEvent> out = handle(*it);
      ++consumed;
      guarded("reading a chunk", [&] {
        ++it;
        return 0;
      });
      if (out) return out;
    }
  } catch (const std::exception&) {
    failure = std::current_exception();
    throw;
  }
  finish();
  return std::nullopt;
}

RosbagReader::RosbagReader(const std::string& path, RosbagReaderOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->opt = std::move(options);
  impl_->open();
}

RosbagReader::~RosbagReader() = default;

bool RosbagReader::next(SensorEvent& out) {
  Impl& d = *impl_;
  if (d.failure) std::rethrow_exception(d.failure);
  // Read on until the oldest waiting event can no longer be overtaken by a later message.
  while (!d.bag_done &&
         (d.reorder.empty() || d.reorder.begin()->first.first >= d.newest_ns - d.opt.reorder_window_ns)) {
    std::optional<SensorEvent> e = d.next_in_bag_order();
    if (!e) {
      d.bag_done = true;
      break;
    }
    const int64_t t = event_time_ns(*e);
    if (t < d.newest_ns - d.opt.reorder_window_ns) {
      try {
        d.fail(
            fmt::format("{}: stamp {} ns is {} ms older than data already read from other topics (more than "
                        "reorder_window_ns = {} ms)",
                        d.last_source, t, (d.newest_ns - t) / 1'000'000, d.opt.reorder_window_ns / 1'000'000));
      } catch (const InputError&) {
        d.failure = std::current_exception();
        throw;
      }
    }
    d.newest_ns = std::max(d.newest_ns, t);
    d.reorder.emplace(std::make_pair(t, d.arrivals++), std::move(*e));
  }
  if (d.reorder.empty()) return false;
  auto first = d.reorder.begin();
  out = std::move(first->second);
  d.reorder.erase(first);
  return true;
}

double RosbagReader::progress() const {
  return impl_->total > 0 ? static_cast<double>(impl_->consumed) / static_cast<double>(impl_->total) : 1.0;
}

std::string RosbagReader::describe() const {
  const Impl& d = *impl_;
  std::string topics;
  for (int s = 0; s < kStreamCount; ++s)
    if (!d.topic_of[s].empty())
      topics += fmt::format("{}{} {}", topics.empty() ? "" : ", ", stream_name(s), d.topic_of[s]);
  return fmt::format("{} (ROS bag: {})", d.path, topics);
}

std::optional<SensorEvent> RosbagReader::next_in_bag_order() { return impl_->next_in_bag_order(); }

RosbagReadStats RosbagReader::read_all(const RosbagCallbacks& callbacks) {
  while (auto msg = next_in_bag_order()) {
    if (auto* f = std::get_if<StereoFrame>(&*msg)) {
      if (callbacks.on_frame) callbacks.on_frame(std::move(*f));
    } else if (auto* imu = std::get_if<ImuSample>(&*msg)) {
      if (callbacks.on_imu) callbacks.on_imu(std::move(*imu));
    } else if (auto* gt = std::get_if<GroundTruthState>(&*msg)) {
      if (callbacks.on_ground_truth) callbacks.on_ground_truth(std::move(*gt));
    }
  }
  return impl_->stats;
}

const RosbagReadStats& RosbagReader::stats() const { return impl_->stats; }
const std::vector<RosbagTopicInfo>& RosbagReader::topics() const { return impl_->topics; }
const std::string& RosbagReader::path() const { return impl_->path; }
const RosbagReaderOptions& RosbagReader::options() const { return impl_->opt; }

}  // namespace dynavins::io
