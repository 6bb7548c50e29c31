// Sensor events through LCM logs: a recording converted to a log replays unchanged.
#include <filesystem>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "io/euroc_source.hpp"
#include "pipeline/lcm_channels.hpp"
#include "pipeline/sensor_log.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;
namespace fs = std::filesystem;

namespace {

const std::string kMicro = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";

fs::path temp_log(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_sensor_log";
  fs::create_directories(dir);
  return dir / name;
}

ImuSample imu_at(int64_t t_ns) {
  ImuSample s;
  s.t_ns = t_ns;
  s.acc = {0, 0, 9.81};
  return s;
}

}  // namespace

TEST_CASE("The real EuRoC clip round-trips through an LCM log unchanged", "[sensorlog][real]") {
  const auto path = temp_log("micro.lcmlog");
  auto data = std::make_shared<io::EurocDataset>(kMicro);
  {
    io::EurocSource src(data);
    LcmLogWriter log(path.string());
    SensorEvent e;
    while (src.next(e)) write_sensor_event(log, e, ImageEncoding::Png);
    log.close();
  }
  io::EurocSource direct(data);
  LcmLogSource replayed(path.string());
  SensorEvent a, b;
  int64_t frames = 0, imu = 0;
  while (direct.next(a)) {
    REQUIRE(replayed.next(b));
    REQUIRE(a.index() == b.index());
    // Microseconds on the wire (DESIGN.md §3): EuRoC's nanosecond stamps come back rounded.
    REQUIRE(std::abs(event_time_ns(a) - event_time_ns(b)) <= 500);
    if (const auto* fa = std::get_if<StereoFrame>(&a)) {
      const auto& fb = std::get<StereoFrame>(b);
      REQUIRE(cv::norm(fa->left, fb.left, cv::NORM_INF) == 0);
      REQUIRE(cv::norm(fa->right, fb.right, cv::NORM_INF) == 0);
      ++frames;
    } else if (const auto* sa = std::get_if<ImuSample>(&a)) {
      REQUIRE(sa->acc == std::get<ImuSample>(b).acc);
      REQUIRE(sa->gyr == std::get<ImuSample>(b).gyr);
      ++imu;
    }
  }
  CHECK_FALSE(replayed.next(b));
  CHECK(frames == 95);
  CHECK(imu > 900);  // the images' 4.7 s plus a second each side, at 200 Hz
  CHECK(replayed.progress() == 1.0);
}

TEST_CASE("LcmLogSource: labels rejoin their frame, unknown channels are skipped and counted", "[sensorlog]") {
  const auto path = temp_log("labels.lcmlog");
  {
    LcmLogWriter log(path.string());
    StereoFrame f;
    f.t_ns = 1'000'000;
    f.left = cv::Mat(4, 6, CV_8UC1, cv::Scalar(7));
    f.right = f.left.clone();
    f.labels = cv::Mat(4, 6, CV_8UC1, cv::Scalar(2));
    write_sensor_event(log, f, ImageEncoding::Gray8);
    log.write_raw("SOMETHING_ELSE", 5, {1, 2, 3});
    write_sensor_event(log, imu_at(2'000'000), ImageEncoding::Gray8);
    log.close();
  }
  LcmLogSource src(path.string());
  SensorEvent e;
  REQUIRE(src.next(e));
  const auto& f = std::get<StereoFrame>(e);
  REQUIRE_FALSE(f.labels.empty());
  CHECK(f.labels.at<uint8_t>(3, 5) == 2);
  REQUIRE(src.next(e));
  CHECK(std::holds_alternative<ImuSample>(e));
  CHECK_FALSE(src.next(e));
  CHECK(src.skipped().at("SOMETHING_ELSE") == 1);
}

TEST_CASE("LcmLogSource restores time order across channels within the reorder window", "[sensorlog]") {
  const auto path = temp_log("reorder.lcmlog");
  {
    LcmLogWriter log(path.string());
    GroundTruthState gt;
    gt.t_ns = 40'000'000;  // logged before IMU samples that are older
    log.write(channels::kGroundTruth, 0, to_lcm(gt));
    for (int i = 0; i < 10; ++i) write_sensor_event(log, imu_at(i * 5'000'000), ImageEncoding::Gray8);
    log.close();
  }
  LcmLogSource src(path.string());
  SensorEvent e;
  int64_t last = INT64_MIN;
  int n = 0;
  while (src.next(e)) {
    CHECK(event_time_ns(e) >= last);
    last = event_time_ns(e);
    ++n;
  }
  CHECK(n == 11);
}

TEST_CASE("LcmLogSource: a channel going back in time or repeating is an error naming the event", "[sensorlog]") {
  const auto path = temp_log("backwards.lcmlog");
  {
    LcmLogWriter log(path.string());
    write_sensor_event(log, imu_at(10'000'000), ImageEncoding::Gray8);
    write_sensor_event(log, imu_at(10'000'000), ImageEncoding::Gray8);
    log.close();
  }
  LcmLogSource src(path.string());
  SensorEvent e;
  CHECK_THROWS_WITH(src.next(e), Catch::Contains(path.string()) && Catch::Contains("event #1") &&
                                     Catch::Contains("channel IMU") && Catch::Contains("repeats"));
}
