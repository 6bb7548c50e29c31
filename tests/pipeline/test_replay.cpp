#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "pipeline/clock.hpp"
#include "pipeline/replay.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

/// 1 s of data: 200 Hz IMU and a 20 Hz frame every 10th sample.
class SyntheticSource final : public io::SensorSource {
 public:
  bool next(SensorEvent& out) override {
    if (k_ > 200) return false;
    const int64_t t = k_ * 5'000'000;
    if (k_ % 10 == 0 && !frame_done_) {
      ImuSample s;  // IMU first at a frame's stamp
      s.t_ns = t;
      out = s;
      frame_done_ = true;
      return true;
    }
    if (frame_done_) {
      StereoFrame f;
      f.t_ns = t;
      f.left = cv::Mat(2, 2, CV_8UC1);
      out = f;
      frame_done_ = false;
      ++k_;
      return true;
    }
    ImuSample s;
    s.t_ns = t;
    out = s;
    ++k_;
    return true;
  }
  double progress() const override { return k_ / 201.0; }
  std::string describe() const override { return "synthetic"; }

 private:
  int64_t k_ = 0;
  bool frame_done_ = false;
};

}  // namespace

TEST_CASE("replay at full speed hands over every event in time order", "[replay]") {
  SyntheticSource src;
  std::vector<int64_t> times;
  int frames = 0, imu = 0;
  ReplaySinks sinks;
  sinks.frame = [&](StereoFrame&& f) { times.push_back(f.t_ns), ++frames; return true; };
  sinks.imu = [&](ImuSample&& s) { times.push_back(s.t_ns), ++imu; return true; };
  StopFlag stop;
  const ReplayStats st = replay(src, {0.0, false}, sinks, stop);
  CHECK(frames == 21);
  CHECK(imu == 201);
  CHECK(st.frames == 21);
  CHECK(st.imu == 201);
  CHECK(st.sensor_s == Approx(1.0));
  for (std::size_t i = 1; i < times.size(); ++i) REQUIRE(times[i] >= times[i - 1]);
}

TEST_CASE("paced replay never runs ahead of its schedule", "[replay]") {
  SyntheticSource src;
  std::vector<int64_t> wall;  // hand-over wall time of each frame
  ReplaySinks sinks;
  sinks.frame = [&](StereoFrame&&) { wall.push_back(steady_now_ns()); return true; };
  sinks.imu = [](ImuSample&&) { return true; };
  StopFlag stop;
  const double rate = 4.0;  // 1 s of data in 0.25 s
  const int64_t start = steady_now_ns();
  const ReplayStats st = replay(src, {rate, false}, sinks, stop);
  REQUIRE(wall.size() == 21);
  for (std::size_t i = 0; i < wall.size(); ++i) {
    const auto due = static_cast<int64_t>(static_cast<double>(i) * 50e6 / rate);
    REQUIRE(wall[i] - start >= due);  // a lower bound only: machines are noisy, never early
  }
  CHECK(st.pacing_error.count == 222);
}

TEST_CASE("replay stops at a stop request", "[replay]") {
  SyntheticSource src;
  StopFlag stop;
  int frames = 0;
  ReplaySinks sinks;
  sinks.frame = [&](StereoFrame&&) {
    if (++frames == 5) stop.request_stop();
    return true;
  };
  sinks.imu = [](ImuSample&&) { return true; };
  const ReplayStats st = replay(src, {0.0, false}, sinks, stop);
  CHECK(st.stopped);
  CHECK(st.frames == 5);
}
