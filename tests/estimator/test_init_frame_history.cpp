// InitFrameHistory and join_intervals: the frames kept before a mono initialisation, and every other one
// of them with its IMU joined over the frame skipped.
#include <catch2/catch.hpp>

#include <cmath>

#include "stages/estimator/initialization/init_frame_history.hpp"
#include "stages/imu/imu_preintegration.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {
constexpr int64_t kFramePeriodNs = 50'000'000;  // 20 Hz frames
constexpr int64_t kImuPeriodNs = 5'000'000;      // 200 Hz IMU

ImuSample sample_at(int64_t t_ns) {
  const double t = t_ns * 1e-9;
  ImuSample s;
  s.t_ns = t_ns;
  s.acc = Eigen::Vector3d(0.5 * std::sin(3 * t), 0.2 * std::cos(2 * t), 9.81 + 0.1 * std::sin(t));
  s.gyr = Eigen::Vector3d(0.1 * std::cos(t), 0.2 * std::sin(2 * t), 0.05);
  return s;
}

/// The IMU over [t0, t1], linearised at zero biases.
imu::ImuPreintegration integrate(int64_t t0, int64_t t1) {
  imu::ImuPreintegration p(sample_at(t0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), imu::ImuNoiseParams{});
  for (int64_t t = t0 + kImuPeriodNs; t <= t1; t += kImuPeriodNs) p.integrate(sample_at(t));
  return p;
}

PreintegratedInterval interval(int64_t t0, int64_t t1) {
  PreintegratedInterval iv;
  iv.t_begin_ns = t0;
  iv.t_end_ns = t1;
  iv.preint = integrate(t0, t1).deltas();
  iv.num_raw_samples = static_cast<int>((t1 - t0) / kImuPeriodNs);
  return iv;
}

TrackedFrame frame(int k) {
  TrackedFrame f;
  f.t_ns = k * kFramePeriodNs;
  f.seq = k;
  TrackedFeature tf;
  tf.id = 100 + k;
  f.features.push_back(tf);
  return f;
}
}  // namespace

TEST_CASE("two intervals joined equal one preintegration over both", "[estimator][initialization]") {
  const PreintegratedInterval joined = join_intervals(interval(0, kFramePeriodNs),
                                                      interval(kFramePeriodNs, 2 * kFramePeriodNs));
  const imu::ImuPreintegration whole = integrate(0, 2 * kFramePeriodNs);
  CHECK(joined.t_begin_ns == 0);
  CHECK(joined.t_end_ns == 2 * kFramePeriodNs);
  CHECK(joined.num_raw_samples == 20);
  CHECK(joined.preint.samples.size() == whole.samples().size());
  CHECK(joined.preint.sum_dt == Approx(whole.sum_dt()));
  CHECK((joined.preint.alpha - whole.delta_p()).norm() < 1e-12);
  CHECK((joined.preint.beta - whole.delta_v()).norm() < 1e-12);
  CHECK(joined.preint.gamma.angularDistance(whole.delta_q()) < 1e-12);
  CHECK((joined.preint.covariance - whole.covariance()).norm() < 1e-12 * whole.covariance().norm());
  CHECK((joined.preint.jacobian - whole.jacobian()).norm() < 1e-9);

  // Intervals that do not meet are refused, naming both times.
  CHECK_THROWS_WITH(join_intervals(interval(0, kFramePeriodNs), interval(2 * kFramePeriodNs, 3 * kFramePeriodNs)),
                    Catch::Contains("ends at 50000000 ns") && Catch::Contains("begins at 100000000 ns"));
}

TEST_CASE("the history keeps the latest frames and strides back from the newest", "[estimator][initialization]") {
  InitFrameHistory h(5);
  CHECK_THROWS(InitFrameHistory(0));
  h.push(frame(0), nullptr);
  for (int k = 1; k < 8; ++k) {
    const PreintegratedInterval iv = interval((k - 1) * kFramePeriodNs, k * kFramePeriodNs);
    h.push(frame(k), &iv);
    CHECK(h.size() == std::min(k + 1, 5));
  }
  CHECK(h.full());

  // Frames 3..7 kept; stride 2 gives 3, 5, 7, each with the IMU from the frame two before.
  const std::vector<HistoryFrame> s = h.strided(2);
  REQUIRE(s.size() == 3);
  for (int i = 0; i < 3; ++i) {
    CHECK(s[i].frame.seq == 3 + 2 * i);
    CHECK(s[i].frame.features.at(0).id == 103 + 2 * i);
  }
  CHECK_FALSE(s[0].imu.has_value());
  for (int i = 1; i < 3; ++i) {
    REQUIRE(s[i].imu.has_value());
    CHECK(s[i].imu->t_begin_ns == s[i - 1].frame.t_ns);
    CHECK(s[i].imu->t_end_ns == s[i].frame.t_ns);
    const imu::ImuPreintegration whole = integrate(s[i - 1].frame.t_ns, s[i].frame.t_ns);
    CHECK((s[i].imu->preint.alpha - whole.delta_p()).norm() < 1e-12);
  }

  // Stride 1 is the frames as kept; a stride that does not divide the span starts later than the oldest.
  CHECK(h.strided(1).size() == 5);
  const std::vector<HistoryFrame> s3 = h.strided(3);
  REQUIRE(s3.size() == 2);
  CHECK(s3[0].frame.seq == 4);
  CHECK(s3[1].frame.seq == 7);
  // At most max_frames, counted back from the newest.
  const std::vector<HistoryFrame> s2 = h.strided(2, 2);
  REQUIRE(s2.size() == 2);
  CHECK(s2[0].frame.seq == 5);
  CHECK(s2[1].frame.seq == 7);
  CHECK(h.strided(1, 1).size() == 1);
  CHECK(h.strided(1, 9).size() == 5);
  CHECK_THROWS(h.strided(1, -1));

  h.clear();
  CHECK(h.size() == 0);
  CHECK(h.strided(2).empty());
}
