// RosbagReader: bags written here with rosbag::Bag (no ROS master), read back field by field,
// plus the bad inputs: wrong topic type, missing topic, colour and unsupported encodings, bad
// stamps, truncated and corrupted files.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include <opencv2/core.hpp>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include "io/rosbag/rosbag_reader.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using dynavins::GroundTruthState;
using dynavins::ImuSample;
using dynavins::SensorEvent;
using dynavins::StereoFrame;
using dynavins::io::BadStampPolicy;
using dynavins::io::RosbagCallbacks;
using dynavins::io::RosbagReader;
using dynavins::io::RosbagReaderOptions;
using dynavins::io::TwistFrame;

namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kUs = 1'000;
constexpr int64_t kT0 = 1'600'000'000LL * 1'000'000'000LL;  // a plausible wall-clock stamp
constexpr int kWorld = 8;
constexpr int kH = 6;

// A fresh directory per test case, removed afterwards.
struct TempDir {
  fs::path dir;
  TempDir() {
    static int counter = 0;
    dir = fs::temp_directory_path() /
          ("dynavins_test_rosbag_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string file(const std::string& name) const { return (dir / name).string(); }
};

ros::Time ros_time(int64_t ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

// Pixel (r, c) of a synthetic gray image: distinct per image via `seed`.
uint8_t pixel(int seed, int r, int c) { return static_cast<uint8_t>(seed * 37 + r * 11 + c * 3); }

cv::Mat expected_gray(int seed) {
  cv::Mat m(kH, kWorld, CV_8UC1);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kWorld; ++c) m.at<uint8_t>(r, c) = pixel(seed, r, c);
  return m;
}

// mono8 with `pad` extra bytes per row, so the reader must honour `step`.
sensor_msgs::Image mono_image(int64_t t_ns, int seed, int pad = 0) {
  sensor_msgs::Image img;
  img.header.stamp = ros_time(t_ns);
  img.header.frame_id = "cam";
  img.height = kH;
  img.width = kWorld;
  img.encoding = "mono8";
  img.step = kWorld + pad;
  img.data.assign(img.step * kH, 0xEE);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kWorld; ++c) img.data[r * img.step + c] = pixel(seed, r, c);
  return img;
}

sensor_msgs::Imu imu_msg(int64_t t_ns, int k) {
  sensor_msgs::Imu m;
  m.header.stamp = ros_time(t_ns);
  m.header.frame_id = "imu";
  m.linear_acceleration.x = 0.01 * k;
  m.linear_acceleration.y = -1.0;
  m.linear_acceleration.z = 9.81 + 0.001 * k;
  m.angular_velocity.x = 0.1;
  m.angular_velocity.y = 0.2 * k;
  m.angular_velocity.z = -0.3;
  return m;
}

Eigen::Vector3d gt_position(int k) { return Eigen::Vector3d(0.1 * k, 0.2 * k, -0.1 * k); }
Eigen::Quaterniond gt_rotation(int k) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d::UnitX()));
}
const Eigen::Vector3d kTwistLinear(1.0, 0.5, -0.25);

nav_msgs::Odometry odom_msg(int64_t t_ns, int k, const std::string& child_frame = "body") {
  nav_msgs::Odometry m;
  m.header.stamp = ros_time(t_ns);
  m.header.frame_id = "world";
  m.child_frame_id = child_frame;
  const Eigen::Vector3d p = gt_position(k);
  const Eigen::Quaterniond q = gt_rotation(k);
  m.pose.pose.position.x = p.x();
  m.pose.pose.position.y = p.y();
  m.pose.pose.position.z = p.z();
  m.pose.pose.orientation.w = q.w();
  m.pose.pose.orientation.x = q.x();
  m.pose.pose.orientation.y = q.y();
  m.pose.pose.orientation.z = q.z();
  m.twist.twist.linear.x = kTwistLinear.x();
  m.twist.twist.linear.y = kTwistLinear.y();
  m.twist.twist.linear.z = kTwistLinear.z();
  return m;
}

// What the VIODE-like bag below holds, and what the reader must give back.
constexpr int kImuCount = 100;  // 200 Hz for 0.5 s
constexpr int kPairs = 10;      // 20 Hz stereo
constexpr int kOdomCount = 25;  // 50 Hz
int64_t imu_stamp(int k) { return kT0 + 5 * kMs * k; }
int64_t left_stamp(int j) { return kT0 + 2500 * kUs + 50 * kMs * j; }
int64_t right_stamp(int j) { return left_stamp(j) + (j % 2 ? 300 * kUs : 0); }  // odd pairs 0.3 ms apart
int64_t odom_stamp(int k) { return kT0 + 1250 * kUs + 20 * kMs * k; }
// Bag (receive) times: never equal across messages, and right before left on even pairs.
int64_t imu_bag_time(int k) { return imu_stamp(k) + 1 * kMs; }
int64_t left_bag_time(int j) { return left_stamp(j) + 2200 * kUs; }
int64_t right_bag_time(int j) { return right_stamp(j) + (j % 2 ? 2300 : 2100) * kUs; }
int64_t odom_bag_time(int k) { return odom_stamp(k) + 500 * kUs; }
// One left image with no right partner at the end, one right image with no left partner mid-way.
int64_t lone_left_stamp() { return left_stamp(kPairs); }
int64_t lone_right_stamp() { return left_stamp(5) + 25 * kMs; }

void write_viode_like_bag(const std::string& path, rosbag::compression::CompressionType compression) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression);
  bag.setChunkThreshold(2048);  // many chunks, so reading crosses chunk boundaries
  for (int k = 0; k < kImuCount; ++k) bag.write("/imu0", ros_time(imu_bag_time(k)), imu_msg(imu_stamp(k), k));
  for (int j = 0; j < kPairs; ++j) {
    bag.write("/cam0/image_raw", ros_time(left_bag_time(j)), mono_image(left_stamp(j), 2 * j));
    bag.write("/cam1/image_raw", ros_time(right_bag_time(j)), mono_image(right_stamp(j), 2 * j + 1, 4));
  }
  bag.write("/cam0/image_raw", ros_time(lone_left_stamp() + 2 * kMs), mono_image(lone_left_stamp(), 90));
  bag.write("/cam1/image_raw", ros_time(lone_right_stamp() + 2 * kMs), mono_image(lone_right_stamp(), 91));
  for (int k = 0; k < kOdomCount; ++k) bag.write("/odometry", ros_time(odom_bag_time(k)), odom_msg(odom_stamp(k), k));
  // A topic the reader does not use: listed, otherwise ignored.
  for (int k = 0; k < 3; ++k) bag.write("/other/imu", ros_time(imu_bag_time(k) + 10 * kUs), imu_msg(imu_stamp(k), k));
  bag.close();
}

// Expected output events in bag-time order: a frame appears when its later image arrives.
struct Expected {
  int64_t bag_time;
  int kind;  // 0 frame, 1 imu, 2 ground truth
  int index;
};
std::vector<Expected> expected_events() {
  std::vector<Expected> ev;
  for (int k = 0; k < kImuCount; ++k) ev.push_back({imu_bag_time(k), 1, k});
  for (int j = 0; j < kPairs; ++j) ev.push_back({std::max(left_bag_time(j), right_bag_time(j)), 0, j});
  for (int k = 0; k < kOdomCount; ++k) ev.push_back({odom_bag_time(k), 2, k});
  std::sort(ev.begin(), ev.end(), [](const Expected& a, const Expected& b) { return a.bag_time < b.bag_time; });
  return ev;
}

bool same_image(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && cv::countNonZero(a != b) == 0;
}

// Everything in bag time order.
std::vector<SensorEvent> read_everything(RosbagReader& reader) {
  std::vector<SensorEvent> out;
  while (auto m = reader.next_in_bag_order()) out.push_back(std::move(*m));
  return out;
}

// A bag with only the given images on /cam0 and /cam1 (pairs at identical stamps) plus IMU and
// odometry, for the encoding cases.
void write_image_bag(const std::string& path, const std::vector<sensor_msgs::Image>& left) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (std::size_t j = 0; j < left.size(); ++j) {
    const int64_t t = kT0 + 50 * kMs * static_cast<int64_t>(j);
    sensor_msgs::Image l = left[j];
    l.header.stamp = ros_time(t);
    bag.write("/cam0/image_raw", ros_time(t + kMs), l);
    bag.write("/cam1/image_raw", ros_time(t + kMs + 1), mono_image(t, 7));
  }
  bag.write("/imu0", ros_time(kT0), imu_msg(kT0, 0));
  bag.write("/odometry", ros_time(kT0), odom_msg(kT0, 0));
  bag.close();
}

// An 8x6 image in a 3- or 4-channel encoding with per-pixel distinct colours.
sensor_msgs::Image colour_image(const std::string& encoding) {
  const int ch = (encoding == "bgra8" || encoding == "rgba8") ? 4 : 3;
  sensor_msgs::Image img;
  img.height = kH;
  img.width = kWorld;
  img.encoding = encoding;
  img.step = kWorld * ch;
  img.data.resize(img.step * kH);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kWorld; ++c)
      for (int k = 0; k < ch; ++k)
        img.data[r * img.step + c * ch + k] = static_cast<uint8_t>(20 + 30 * k + 17 * r + 9 * c);
  return img;
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}
void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes, std::size_t n) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(n));
}

}  // namespace

TEST_CASE("RosbagReader reads a VIODE-like bag back field by field in bag time order", "[rosbag]") {
  TempDir tmp;
  const auto compression =
      GENERATE(rosbag::compression::Uncompressed, rosbag::compression::LZ4, rosbag::compression::BZ2);
  const std::string path = tmp.file("viode_like.bag");
  write_viode_like_bag(path, compression);

  RosbagReader reader(path);
  REQUIRE(reader.path() == path);
  const auto& topics = reader.topics();
  REQUIRE(topics.size() == 5);
  auto topic = [&](const std::string& name) {
    auto it = std::find_if(topics.begin(), topics.end(), [&](const auto& t) { return t.topic == name; });
    REQUIRE(it != topics.end());
    return *it;
  };
  CHECK(topic("/cam0/image_raw").datatype == "sensor_msgs/Image");
  CHECK(topic("/cam0/image_raw").messages == kPairs + 1);
  CHECK(topic("/cam1/image_raw").messages == kPairs + 1);
  CHECK(topic("/imu0").datatype == "sensor_msgs/Imu");
  CHECK(topic("/imu0").messages == kImuCount);
  CHECK(topic("/odometry").datatype == "nav_msgs/Odometry");
  CHECK(topic("/odometry").messages == kOdomCount);
  CHECK(topic("/other/imu").messages == 3);

  const std::vector<SensorEvent> got = read_everything(reader);
  const std::vector<Expected> want = expected_events();
  REQUIRE(got.size() == want.size());
  for (std::size_t n = 0; n < want.size(); ++n) {
    INFO("output #" << n);
    const Expected& e = want[n];
    REQUIRE(static_cast<int>(got[n].index()) == e.kind);
    if (e.kind == 0) {
      const auto& f = std::get<StereoFrame>(got[n]);
      CHECK(f.t_ns == left_stamp(e.index));
      CHECK(f.seq == e.index);
      CHECK(same_image(f.left, expected_gray(2 * e.index)));
      CHECK(same_image(f.right, expected_gray(2 * e.index + 1)));
      CHECK(f.labels.empty());
    } else if (e.kind == 1) {
      const auto& s = std::get<ImuSample>(got[n]);
      const sensor_msgs::Imu m = imu_msg(imu_stamp(e.index), e.index);
      CHECK(s.t_ns == imu_stamp(e.index));
      CHECK(s.acc == Eigen::Vector3d(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z));
      CHECK(s.gyr == Eigen::Vector3d(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z));
    } else {
      const auto& g = std::get<GroundTruthState>(got[n]);
      CHECK(g.t_ns == odom_stamp(e.index));
      CHECK(g.p_wb == gt_position(e.index));
      CHECK(g.q_wb.angularDistance(gt_rotation(e.index)) < 1e-12);
      // child_frame_id "body" != frame_id "world": the twist is in the body frame.
      CHECK((g.v_wb - gt_rotation(e.index) * kTwistLinear).norm() < 1e-12);
      CHECK(g.has_velocity);
      CHECK_FALSE(g.has_biases);
    }
  }

  const auto& st = reader.stats();
  CHECK(st.stereo_frames == kPairs);
  CHECK(st.left_images == kPairs + 1);
  CHECK(st.right_images == kPairs + 1);
  CHECK(st.unmatched_left == 1);
  CHECK(st.unmatched_right == 1);
  CHECK(st.imu_samples == kImuCount);
  CHECK(st.ground_truth_states == kOdomCount);
  CHECK(st.skipped_bad_stamps == 0);
  CHECK_THAT(st.summary(), Contains("10 stereo frames") && Contains("1 left and 1 right unmatched"));
  CHECK_FALSE(reader.next_in_bag_order());  // stays at the end
}

TEST_CASE("RosbagReader as a SensorSource gives events in sensor time order", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("viode_like.bag");
  write_viode_like_bag(path, rosbag::compression::Uncompressed);

  std::vector<SensorEvent> bag_order;
  {
    RosbagReader reader(path);
    bag_order = read_everything(reader);
  }
  RosbagReader reader(path);
  CHECK_THAT(reader.describe(), Contains(path) && Contains("left image /cam0/image_raw") && Contains("IMU /imu0") &&
                                    Contains("odometry /odometry"));
  CHECK(reader.progress() == 0.0);
  std::vector<SensorEvent> time_order;
  SensorEvent e;
  while (reader.next(e)) time_order.push_back(e);
  CHECK(reader.progress() == 1.0);
  REQUIRE(time_order.size() == bag_order.size());
  for (std::size_t n = 1; n < time_order.size(); ++n) {
    INFO("event #" << n);
    CHECK(dynavins::event_time_ns(time_order[n - 1]) <= dynavins::event_time_ns(time_order[n]));
  }
  // The same events: a stable sort of the bag order by stamp.
  std::stable_sort(bag_order.begin(), bag_order.end(), [](const SensorEvent& a, const SensorEvent& b) {
    return dynavins::event_time_ns(a) < dynavins::event_time_ns(b);
  });
  for (std::size_t n = 0; n < time_order.size(); ++n) {
    CHECK(time_order[n].index() == bag_order[n].index());
    CHECK(dynavins::event_time_ns(time_order[n]) == dynavins::event_time_ns(bag_order[n]));
  }
  CHECK_FALSE(reader.next(e));

  SECTION("disorder beyond the reorder window is an error naming the message") {
    const std::string late = tmp.file("late.bag");
    {
      rosbag::Bag bag(late, rosbag::bagmode::Write);
      bag.write("/cam0/image_raw", ros_time(kT0), mono_image(kT0, 1));
      bag.write("/cam1/image_raw", ros_time(kT0 + 1), mono_image(kT0, 2));
      for (int k = 0; k < 80; ++k) bag.write("/imu0", ros_time(kT0 + 2 + k), imu_msg(imu_stamp(k), k));
      // Stamped 300 ms before the newest IMU sample already read.
      bag.write("/odometry", ros_time(kT0 + 100), odom_msg(imu_stamp(79) - 300 * kMs, 0));
      bag.close();
    }
    RosbagReaderOptions opt;
    RosbagReader strict(late, opt);
    auto drain = [](RosbagReader& r) {
      SensorEvent ev;
      int n = 0;
      while (r.next(ev)) ++n;
      return n;
    };
    CHECK_THROWS_WITH(drain(strict), Contains(late) && Contains("topic /odometry message #0") &&
                                         Contains("300 ms older") && Contains("reorder_window_ns = 200 ms"));
    opt.reorder_window_ns = 500 * kMs;
    RosbagReader relaxed(late, opt);
    CHECK(drain(relaxed) == 1 + 80 + 1);
  }
}

TEST_CASE("RosbagReader options for callbacks and stereo tolerance and pending limit and mono and twist frame",
          "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("viode_like.bag");
  write_viode_like_bag(path, rosbag::compression::Uncompressed);

  SECTION("callbacks see every message") {
    RosbagReader reader(path);
    int frames = 0, imu = 0, gt = 0;
    int64_t last_imu = 0;
    RosbagCallbacks cb;
    cb.on_frame = [&](StereoFrame&& f) { CHECK(f.seq == frames++); };
    cb.on_imu = [&](ImuSample&& s) {
      CHECK(s.t_ns > last_imu);
      last_imu = s.t_ns;
      ++imu;
    };
    cb.on_ground_truth = [&](GroundTruthState&&) { ++gt; };
    const auto st = reader.read_all(cb);
    CHECK(frames == kPairs);
    CHECK(imu == kImuCount);
    CHECK(gt == kOdomCount);
    CHECK(st.stereo_frames == kPairs);
  }
  SECTION("zero tolerance pairs only identical stamps") {
    RosbagReaderOptions opt;
    opt.stereo_tolerance_ns = 0;
    RosbagReader reader(path, opt);
    std::vector<int64_t> stamps;
    RosbagCallbacks cb;
    cb.on_frame = [&](StereoFrame&& f) { stamps.push_back(f.t_ns); };
    const auto st = reader.read_all(cb);
    CHECK(stamps == std::vector<int64_t>{left_stamp(0), left_stamp(2), left_stamp(4), left_stamp(6), left_stamp(8)});
    CHECK(st.unmatched_left == kPairs / 2 + 1);
    CHECK(st.unmatched_right == kPairs / 2 + 1);
  }
  SECTION("a right topic of the wrong type is rejected on open") {
    RosbagReaderOptions opt;
    opt.right_topic = "/other/imu";  // wrong type: rejected before any reading
    CHECK_THROWS_WITH(RosbagReader(path, opt),
                      Contains("/other/imu") && Contains("sensor_msgs/Imu") && Contains("expected sensor_msgs/Image"));
  }
  SECTION("the pending limit drops and counts the oldest waiting images") {
    // All left images arrive before any right image, so they pile up waiting.
    const std::string late = tmp.file("late_right.bag");
    {
      rosbag::Bag bag(late, rosbag::bagmode::Write);
      for (int j = 0; j < 5; ++j)
        bag.write("/cam0/image_raw", ros_time(left_stamp(j) + kMs), mono_image(left_stamp(j), j));
      for (int j = 0; j < 5; ++j)
        bag.write("/cam1/image_raw", ros_time(left_stamp(10) + j), mono_image(left_stamp(j), 10 + j));
      bag.write("/imu0", ros_time(kT0), imu_msg(kT0, 0));
      bag.write("/odometry", ros_time(kT0), odom_msg(kT0, 0));
      bag.close();
    }
    RosbagReaderOptions opt;
    opt.max_pending_images = 2;
    RosbagReader reader(late, opt);
    std::vector<StereoFrame> frames;
    RosbagCallbacks cb;
    cb.on_frame = [&](StereoFrame&& f) { frames.push_back(std::move(f)); };
    const auto st = reader.read_all(cb);
    REQUIRE(frames.size() == 2);  // lefts 3 and 4 were still waiting when their rights came
    CHECK(frames[0].t_ns == left_stamp(3));
    CHECK(same_image(frames[0].left, expected_gray(3)));
    CHECK(same_image(frames[0].right, expected_gray(13)));
    CHECK(frames[1].t_ns == left_stamp(4));
    CHECK(st.unmatched_left == 3);
    CHECK(st.unmatched_right == 3);
  }
  SECTION("mono mode: no right topic") {
    RosbagReaderOptions opt;
    opt.right_topic = "";
    RosbagReader reader(path, opt);
    std::vector<StereoFrame> frames;
    RosbagCallbacks cb;
    cb.on_frame = [&](StereoFrame&& f) { frames.push_back(std::move(f)); };
    const auto st = reader.read_all(cb);
    REQUIRE(frames.size() == kPairs + 1);
    CHECK(frames[3].t_ns == left_stamp(3));
    CHECK(same_image(frames[3].left, expected_gray(6)));
    CHECK(frames[3].right.empty());
    CHECK(st.unmatched_left == 0);
    CHECK(st.right_images == 0);
  }
  SECTION("twist frame overrides") {
    RosbagReaderOptions opt;
    opt.twist_frame = TwistFrame::World;
    RosbagReader world(path, opt);
    std::vector<GroundTruthState> gts;
    RosbagCallbacks cb;
    cb.on_ground_truth = [&](GroundTruthState&& g) { gts.push_back(g); };
    world.read_all(cb);
    REQUIRE(gts.size() == kOdomCount);
    CHECK(gts[7].v_wb == kTwistLinear);
    CHECK(gts[7].has_velocity);

    opt.twist_frame = TwistFrame::Ignore;
    RosbagReader ignore(path, opt);
    gts.clear();
    ignore.read_all(cb);
    REQUIRE(gts.size() == kOdomCount);
    CHECK_FALSE(gts[7].has_velocity);
    CHECK(gts[7].v_wb == Eigen::Vector3d::Zero());
  }
}

TEST_CASE("RosbagReader odometry without child frame has its twist in the world", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("odom_world.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/odometry", ros_time(kT0), odom_msg(kT0, 9, ""));
    bag.close();
  }
  RosbagReaderOptions opt;
  opt.right_topic = "";
  opt.imu_topic = "";
  opt.left_topic = "/odometry_images_unused";
  CHECK_THROWS_WITH(RosbagReader(path, opt), Contains(path) && Contains("/odometry_images_unused") &&
                                                 Contains("not in the bag") &&
                                                 Contains("/odometry [nav_msgs/Odometry]"));
  // Only the left topic is mandatory, so give the bag one image.
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/cam0/image_raw", ros_time(kT0), mono_image(kT0, 1));
    bag.write("/odometry", ros_time(kT0 + 1), odom_msg(kT0, 9, ""));
    bag.close();
  }
  opt.left_topic = "/cam0/image_raw";
  RosbagReader reader(path, opt);
  const auto got = read_everything(reader);
  REQUIRE(got.size() == 2);
  const auto& g = std::get<GroundTruthState>(got[1]);
  CHECK(g.v_wb == kTwistLinear);
  CHECK(g.has_velocity);
}

TEST_CASE("RosbagReader converts colour encodings to gray", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("colour.bag");
  const std::vector<std::string> encodings = {"bgr8", "rgb8", "bgra8", "rgba8"};
  std::vector<sensor_msgs::Image> left;
  for (const auto& e : encodings) left.push_back(colour_image(e));
  write_image_bag(path, left);

  RosbagReader reader(path);
  std::vector<StereoFrame> frames;
  RosbagCallbacks cb;
  cb.on_frame = [&](StereoFrame&& f) { frames.push_back(std::move(f)); };
  reader.read_all(cb);
  REQUIRE(frames.size() == encodings.size());
  for (std::size_t j = 0; j < encodings.size(); ++j) {
    INFO(encodings[j]);
    const cv::Mat& g = frames[j].left;
    REQUIRE(g.type() == CV_8UC1);
    REQUIRE(g.size() == cv::Size(kWorld, kH));
    const bool bgr = encodings[j][0] == 'b';
    const int ch = encodings[j].size() == 5 ? 4 : 3;
    for (int r = 0; r < kH; ++r)
      for (int c = 0; c < kWorld; ++c) {
        const uint8_t* px = &left[j].data[r * left[j].step + c * ch];
        const double b = bgr ? px[0] : px[2], gr = px[1], rd = bgr ? px[2] : px[0];
        // ITU-R BT.601 luma, as OpenCV's cvtColor computes it (fixed point: within 1).
        CHECK(std::abs(g.at<uint8_t>(r, c) - (0.114 * b + 0.587 * gr + 0.299 * rd)) <= 1.0);
      }
  }
}

TEST_CASE("RosbagReader rejects bad images naming the topic and message", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("bad_image.bag");
  std::vector<sensor_msgs::Image> left = {mono_image(0, 1), mono_image(0, 2), mono_image(0, 3)};

  SECTION("unsupported encoding") {
    left[2].encoding = "mono16";
    write_image_bag(path, left);
    RosbagReader reader(path);
    REQUIRE(reader.next_in_bag_order());  // the first pairs read fine
    std::string what;
    try {
      while (reader.next_in_bag_order()) {
      }
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
    CHECK_THAT(what, Contains(path) && Contains("/cam0/image_raw") && Contains("message #2") &&
                         Contains("unsupported image encoding 'mono16'"));
    // The reader stays failed rather than skipping on.
    CHECK_THROWS_WITH(reader.next_in_bag_order(), Contains("message #2"));
    SensorEvent e;
    CHECK_THROWS_WITH(reader.next(e), Contains("message #2"));
  }
  SECTION("data shorter than step x height") {
    left[1].data.resize(left[1].data.size() - 1);
    write_image_bag(path, left);
    RosbagReader reader(path);
    CHECK_THROWS_WITH(read_everything(reader),
                      Contains(path) && Contains("/cam0/image_raw") && Contains("message #1") && Contains("47 bytes"));
  }
  SECTION("step shorter than a row") {
    left[0].step = kWorld - 1;
    left[0].data.resize(left[0].step * kH);
    write_image_bag(path, left);
    RosbagReader reader(path);
    CHECK_THROWS_WITH(read_everything(reader), Contains("message #0") && Contains("step 7"));
  }
}

TEST_CASE("RosbagReader checks topics and their types on open", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("wrong_type.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/cam0/image_raw", ros_time(kT0), mono_image(kT0, 1));
    bag.write("/cam1/image_raw", ros_time(kT0), mono_image(kT0, 2));
    bag.write("/imu0", ros_time(kT0), mono_image(kT0, 3));  // an image where the IMU should be
    bag.write("/odometry", ros_time(kT0), odom_msg(kT0, 0));
    bag.close();
  }
  CHECK_THROWS_WITH(RosbagReader(path), Contains(path) && Contains("/imu0") && Contains("has type sensor_msgs/Image") &&
                                            Contains("expected sensor_msgs/Imu"));

  RosbagReaderOptions opt;
  opt.imu_topic = "";
  opt.odometry_topic = "/ground_truth";
  CHECK_THROWS_WITH(RosbagReader(path, opt), Contains("/ground_truth") && Contains("not in the bag"));

  opt.odometry_topic = "/cam0/image_raw";
  CHECK_THROWS_WITH(RosbagReader(path, opt), Contains("configured for both"));
}

TEST_CASE("RosbagReader stamps going backwards or repeating", "[rosbag]") {
  TempDir tmp;
  const std::string path = tmp.file("stamps.bag");
  {
    rosbag::Bag bag(path, rosbag::bagmode::Write);
    bag.write("/cam0/image_raw", ros_time(kT0), mono_image(kT0, 1));
    bag.write("/cam1/image_raw", ros_time(kT0 + 1), mono_image(kT0, 2));
    const int64_t stamps[] = {kT0, kT0 + 5 * kMs, kT0 + 10 * kMs, kT0 + 10 * kMs, kT0 + 7 * kMs, kT0 + 20 * kMs};
    for (int k = 0; k < 6; ++k) bag.write("/imu0", ros_time(kT0 + 2 + k), imu_msg(stamps[k], k));
    bag.write("/odometry", ros_time(kT0 + 100), odom_msg(kT0, 0));
    bag.close();
  }
  SECTION("default: an error naming topic and index") {
    RosbagReader reader(path);
    CHECK_THROWS_WITH(read_everything(reader),
                      Contains(path) && Contains("/imu0") && Contains("message #3") && Contains("duplicate"));
  }
  SECTION("skip and count") {
    RosbagReaderOptions opt;
    opt.bad_stamp = BadStampPolicy::SkipAndCount;
    RosbagReader reader(path, opt);
    std::vector<int> ks;
    RosbagCallbacks cb;
    cb.on_imu = [&](ImuSample&& s) { ks.push_back(static_cast<int>(std::lround(s.acc.x() / 0.01))); };
    const auto st = reader.read_all(cb);
    CHECK(ks == std::vector<int>{0, 1, 2, 5});
    CHECK(st.skipped_bad_stamps == 2);
    CHECK(st.imu_samples == 4);
  }
}

TEST_CASE("RosbagReader truncated or corrupt or missing files are errors naming the file", "[rosbag]") {
  TempDir tmp;
  const std::string good = tmp.file("good.bag");
  write_viode_like_bag(good, rosbag::compression::Uncompressed);
  const std::vector<uint8_t> bytes = read_bytes(good);
  REQUIRE(bytes.size() > 4096);

  SECTION("cut short") {
    const std::string cut = tmp.file("cut.bag");
    for (std::size_t n : {std::size_t{0}, std::size_t{5}, std::size_t{13}, std::size_t{200}, bytes.size() / 3,
                          bytes.size() / 2, bytes.size() - 200, bytes.size() - 1}) {
      INFO("cut at " << n << " of " << bytes.size() << " bytes");
      write_bytes(cut, bytes, n);
      CHECK_THROWS_WITH(
          [&] {
            RosbagReader reader(cut);
            read_everything(reader);
          }(),
          Contains(cut));
    }
  }
  SECTION("no index (a recording that was never closed)") {
    std::vector<uint8_t> b = bytes;
    const std::string key = "index_pos=";
    const auto at = std::search(b.begin(), b.end(), key.begin(), key.end());
    REQUIRE(at != b.end());
    std::fill(at + static_cast<std::ptrdiff_t>(key.size()), at + static_cast<std::ptrdiff_t>(key.size()) + 8, 0);
    const std::string unindexed = tmp.file("unindexed.bag");
    write_bytes(unindexed, b, b.size());
    CHECK_THROWS_WITH(RosbagReader(unindexed), Contains(unindexed) && Contains("no index"));
  }
  SECTION("not a bag, or no file") {
    const std::string text = tmp.file("text.bag");
    std::ofstream(text) << "this is not a ROS bag\n";
    CHECK_THROWS_WITH(RosbagReader(text), Contains(text));
    CHECK_THROWS_WITH(RosbagReader(tmp.file("missing.bag")), Contains("missing.bag"));
  }
}

TEST_CASE("RosbagReader survives corrupted bytes throughout a small bag", "[rosbag]") {
  // rosbag_storage itself reads out of bounds on a bad index offset or record length; the
  // reader's structure check must turn each such case into an error naming the file. A sample
  // of ~350 positions per bag keeps this quick (every byte was checked once, offline).
  TempDir tmp;
  const auto compression =
      GENERATE(rosbag::compression::Uncompressed, rosbag::compression::LZ4, rosbag::compression::BZ2);
  const std::string good = tmp.file("small.bag");
  {
    rosbag::Bag bag(good, rosbag::bagmode::Write);
    bag.setCompression(compression);
    bag.setChunkThreshold(512);
    for (int k = 0; k < 3; ++k) bag.write("/imu0", ros_time(imu_stamp(k)), imu_msg(imu_stamp(k), k));
    for (int j = 0; j < 2; ++j) {
      bag.write("/cam0/image_raw", ros_time(left_stamp(j)), mono_image(left_stamp(j), j));
      bag.write("/cam1/image_raw", ros_time(left_stamp(j) + 1), mono_image(left_stamp(j), j));
    }
    bag.write("/odometry", ros_time(odom_stamp(0)), odom_msg(odom_stamp(0), 0));
    bag.close();
  }
  const std::vector<uint8_t> bytes = read_bytes(good);
  const std::string bad = tmp.file("corrupt.bag");
  const std::size_t stride = std::max<std::size_t>(1, bytes.size() / 350);
  int read_ok = 0, errors = 0, unnamed = 0;
  for (std::size_t k = 0; k * stride < bytes.size(); ++k) {
    const std::size_t at = std::min(bytes.size() - 1, k * stride + k % stride);  // drift across field offsets
    for (int variant = 0; variant < 2; ++variant) {
      std::vector<uint8_t> b = bytes;
      if (variant == 0) {
        b[at] ^= 0x41;
      } else {
        for (std::size_t i = at; i < std::min(b.size(), at + 4); ++i) b[i] = 0xFF;
      }
      write_bytes(bad, b, b.size());
      try {
        RosbagReader reader(bad);
        read_everything(reader);
        ++read_ok;  // e.g. a changed pixel or padding byte: not detectable, and harmless
      } catch (const std::runtime_error& e) {
        ++errors;
        if (std::string(e.what()).find(bad) == std::string::npos) {
          ++unnamed;
          WARN(e.what());
        }
      }
    }
  }
  INFO(read_ok << " read, " << errors << " errors, file of " << bytes.size() << " bytes");
  CHECK(errors > 0);
  CHECK(unnamed == 0);
}
