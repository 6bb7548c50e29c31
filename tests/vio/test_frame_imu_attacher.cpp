// FrameImuAttacher: each frame leaves with the samples from the last one at or before the previous
// frame to the first one at or after it, which GyroRotationPredictor accepts; a frame dropped
// downstream leaves its successor's samples short of the tracker's previous frame, which it refuses.
#include <catch2/catch.hpp>

#include <optional>
#include <vector>

#include "pipeline/vio/frame_imu_attacher.hpp"
#include "stages/tracker/gyro_rotation_predictor.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

constexpr int64_t kMs = 1'000'000;

ImuSample imu_at(int64_t t) {
  ImuSample s;
  s.t_ns = t;
  s.gyr = Eigen::Vector3d(0.0, 0.0, 1.0);
  return s;
}

StereoFrame frame_at(int64_t t, int64_t seq) {
  StereoFrame f;
  f.t_ns = t;
  f.seq = seq;
  return f;
}

/// Replays 200 Hz IMU (from 0 ms) and 20 Hz frames (from 12 ms, off the IMU grid) in time order, up to `end`.
std::vector<TrackerInput> replay(FrameImuAttacher& a, int64_t end) {
  std::vector<TrackerInput> out;
  auto take = [&](std::optional<TrackerInput> x) {
    if (x) out.push_back(std::move(*x));
  };
  int64_t next_imu = 0, next_frame = 12 * kMs, seq = 0;
  while (next_imu <= end || next_frame <= end) {
    if (next_frame < next_imu) {
      take(a.add_frame(frame_at(next_frame, seq++)));
      next_frame += 50 * kMs;
    } else {
      take(a.add_imu(imu_at(next_imu)));
      next_imu += 5 * kMs;
    }
  }
  take(a.finish());
  return out;
}

std::vector<int64_t> times(const std::vector<ImuSample>& v) {
  std::vector<int64_t> t;
  for (const auto& s : v) t.push_back(s.t_ns / kMs);
  return t;
}

}  // namespace

TEST_CASE("FrameImuAttacher packs each frame with the samples of its interval", "[vio][gyro]") {
  FrameImuAttacher a;
  const auto out = replay(a, 200 * kMs);  // frames at 12, 62, 112, 162 ms
  REQUIRE(out.size() == 4);
  CHECK(out[0].frame.seq == 0);
  CHECK(times(out[0].imu) == std::vector<int64_t>{0, 5, 10, 15});
  CHECK(times(out[1].imu) == std::vector<int64_t>{10, 15, 20, 25, 30, 35, 40, 45, 50, 55, 60, 65});
  CHECK(times(out[3].imu).front() == 110);
  CHECK(times(out[3].imu).back() == 165);
  CHECK(a.released_incomplete() == 0);

  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), 15 * kMs);
  for (std::size_t i = 1; i < out.size(); ++i) {
    const auto R = p.predict(out[i].imu, out[i - 1].frame.t_ns, out[i].frame.t_ns);
    REQUIRE(R);
    CHECK(Eigen::AngleAxisd(*R).angle() == Approx(0.05));  // 1 rad/s for 50 ms
  }
}

TEST_CASE("FrameImuAttacher releases frames on an IMU sample at their exact time", "[vio][gyro]") {
  FrameImuAttacher a;
  CHECK_FALSE(a.add_imu(imu_at(0)));
  CHECK_FALSE(a.add_frame(frame_at(5 * kMs, 0)));
  const auto f0 = a.add_imu(imu_at(5 * kMs));
  REQUIRE(f0);
  CHECK(times(f0->imu) == std::vector<int64_t>{0, 5});
  CHECK_FALSE(a.add_imu(imu_at(10 * kMs)));
  CHECK_FALSE(a.add_frame(frame_at(15 * kMs, 1)));
  const auto f1 = a.add_imu(imu_at(15 * kMs));
  REQUIRE(f1);
  CHECK(times(f1->imu) == std::vector<int64_t>{5, 10, 15});  // starts exactly at the previous frame
}

TEST_CASE("FrameImuAttacher hands a frame on without its end sample when the next frame comes first", "[vio][gyro]") {
  FrameImuAttacher a;
  CHECK_FALSE(a.add_imu(imu_at(0)));
  CHECK_FALSE(a.add_frame(frame_at(2 * kMs, 0)));
  const auto f0 = a.add_frame(frame_at(4 * kMs, 1));  // no IMU between the two frames
  REQUIRE(f0);
  CHECK(f0->frame.seq == 0);
  CHECK(a.released_incomplete() == 1);
  const auto f1 = a.finish();  // end of input
  REQUIRE(f1);
  CHECK(f1->frame.seq == 1);
  CHECK(a.released_incomplete() == 2);
  CHECK_FALSE(a.finish());
  // Neither interval is covered: the predictor refuses rather than extrapolates.
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), 15 * kMs);
  CHECK_FALSE(p.predict(f1->imu, 2 * kMs, 4 * kMs));
}

TEST_CASE("a frame dropped after the attacher leaves the next one without prediction", "[vio][gyro]") {
  FrameImuAttacher a;
  auto out = replay(a, 200 * kMs);
  REQUIRE(out.size() == 4);
  out.erase(out.begin() + 1);  // the frame queue dropped the frame at 62 ms
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), 15 * kMs);
  CHECK_FALSE(p.predict(out[1].imu, out[0].frame.t_ns, out[1].frame.t_ns));  // 12 -> 112 ms: samples start at 60
  CHECK(p.predict(out[2].imu, out[1].frame.t_ns, out[2].frame.t_ns));         // 112 -> 162 ms: covered again
}

TEST_CASE("FrameImuAttacher keeps a bounded buffer while no frame comes", "[vio][gyro]") {
  FrameImuAttacher a(10);
  for (int i = 0; i < 100; ++i) CHECK_FALSE(a.add_imu(imu_at(i * 5 * kMs)));
  CHECK_FALSE(a.add_frame(frame_at(600 * kMs, 0)));
  const auto f = a.add_imu(imu_at(600 * kMs));
  REQUIRE(f);
  CHECK(f->imu.size() == 11);
  CHECK(f->imu.front().t_ns == 450 * kMs);
}
