// LcmLiveSource on memq://: good messages come out as events; foreign, truncated, wrong-size and
// non-finite messages and times going back are counted, never handed on; a stop request ends next().
#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>

#include <dynavins_lcm/imu_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/stereo_image_t.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_live_source.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

StereoFrame frame(int64_t t_ns, int w = 64, int h = 48) {
  StereoFrame f;
  f.t_ns = t_ns;
  f.left = cv::Mat(h, w, CV_8UC1, cv::Scalar(100));
  f.right = f.left.clone();
  return f;
}

ImuSample imu(int64_t t_ns) {
  ImuSample s;
  s.t_ns = t_ns;
  s.acc = {0, 0, 9.81};
  return s;
}

/// Everything the source hands on until its input runs dry (stop set once nothing is left).
std::vector<SensorEvent> collect(lcm::LCM& lcm, LcmLiveSource& src, std::atomic<bool>& stop) {
  std::vector<SensorEvent> out;
  while (lcm.handleTimeout(0) > 0) {
  }
  stop = true;  // everything is already received; next() returns what is waiting, then false
  SensorEvent e;
  while (src.next(e)) out.push_back(e);
  return out;
}

}  // namespace

TEST_CASE("LcmLiveSource: good input comes out, each kind of bad input is counted", "[lcm_live]") {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  LiveSourceOptions opt;
  opt.image_width = 64;
  opt.image_height = 48;
  std::atomic<bool> stop{false};
  LcmLiveSource src(lcm, opt, &stop);

  const auto pub = [&](const char* ch, const auto& msg) { REQUIRE(lcm.publish(ch, &msg) == 0); };
  pub("IMU", to_lcm(imu(1'000'000)));
  pub("CAM_STEREO", to_lcm(frame(1'000'000), ImageEncoding::Gray8));
  pub("IMU", to_lcm(imu(6'000'000)));
  // Another type on the IMU channel (a pose): its fingerprint is not imu_t's.
  dynavins_lcm::pose_t pose{};
  pose.orientation[0] = 1;
  pub("IMU", pose);
  // A truncated IMU payload.
  const dynavins_lcm::imu_t good = to_lcm(imu(7'000'000));
  std::vector<uint8_t> buf(static_cast<size_t>(good.getEncodedSize()));
  good.encode(buf.data(), 0, static_cast<int>(buf.size()));
  REQUIRE(lcm.publish("IMU", buf.data(), static_cast<unsigned>(buf.size() - 5)) == 0);
  // NaN in an IMU sample.
  dynavins_lcm::imu_t nan = to_lcm(imu(8'000'000));
  nan.angular_velocity[1] = std::numeric_limits<double>::quiet_NaN();
  pub("IMU", nan);
  // IMU going back in time.
  pub("IMU", to_lcm(imu(2'000'000)));
  // An image whose data does not match its width and height.
  dynavins_lcm::stereo_image_t bad = to_lcm(frame(2'000'000), ImageEncoding::Gray8);
  bad.left.data.resize(bad.left.data.size() - 10);
  bad.left.size = static_cast<int32_t>(bad.left.data.size());
  pub("CAM_STEREO", bad);
  // An image of another size than the calibration's.
  pub("CAM_STEREO", to_lcm(frame(3'000'000, 32, 24), ImageEncoding::Gray8));
  // A frame going back in time.
  pub("CAM_STEREO", to_lcm(frame(500'000), ImageEncoding::Gray8));
  pub("CAM_STEREO", to_lcm(frame(4'000'000), ImageEncoding::Gray8));

  const std::vector<SensorEvent> ev = collect(lcm, src, stop);
  REQUIRE(ev.size() == 4);
  CHECK(std::holds_alternative<ImuSample>(ev[0]));
  CHECK(std::holds_alternative<StereoFrame>(ev[1]));
  CHECK(std::holds_alternative<ImuSample>(ev[2]));
  CHECK(event_time_ns(ev[3]) == 4'000'000);
  CHECK(std::get<StereoFrame>(ev[1]).left.cols == 64);

  const LiveSourceStats& s = src.stats();
  CHECK(s.frames == 2);
  CHECK(s.imu == 2);
  CHECK(s.wrong_type == 1);
  CHECK(s.undecodable == 1);
  CHECK(s.bad_imu == 1);
  CHECK(s.bad_image == 2);
  CHECK(s.time_went_back == 2);
  CHECK(s.rejected() == 7);
}

TEST_CASE("LcmLiveSource: a stop request ends a wait with no input", "[lcm_live]") {
  lcm::LCM lcm("memq://");
  std::atomic<bool> stop{true};
  LcmLiveSource src(lcm, LiveSourceOptions{}, &stop);
  SensorEvent e;
  CHECK_FALSE(src.next(e));
}
