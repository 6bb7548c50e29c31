// ImuIntervalBuilder: one interval per consecutive frame pair, interleaving-independent, interpolated ends vs
// ground truth, out-of-order rejection with counts, IMU gaps reported.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "sim/motion/imu_simulator.hpp"
#include "stages/common/so3.hpp"
#include "tests/imu/wavy_trajectory.hpp"
#include "stages/imu/imu_interval_builder.hpp"

using namespace dynavins;
using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

std::vector<ImuSample> imu_samples(const SmoothTrajectory& tr, int64_t t0, int64_t t1) {
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  return ImuSimulator(o).simulate(tr, t0, t1).samples;
}

// 20 Hz frames off the 200 Hz IMU grid (offset 1.2345 ms).
std::vector<int64_t> frame_times() {
  std::vector<int64_t> f;
  for (int k = 0; k < 10; ++k) f.push_back(2'001'234'500 + k * 50'000'000LL);
  return f;
}

double max_delta_error(const SmoothTrajectory& tr, const PreintegratedInterval& iv) {
  const KinematicState a = tr.evaluate(iv.t_begin_ns * 1e-9), b = tr.evaluate(iv.t_end_ns * 1e-9);
  const double T = (iv.t_end_ns - iv.t_begin_ns) * 1e-9;
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Vector3d alpha = a.R_wb.transpose() * (b.p_w - a.p_w - a.v_w * T - 0.5 * g * T * T);
  const Eigen::Vector3d beta = a.R_wb.transpose() * (b.v_w - a.v_w - g * T);
  const Eigen::Matrix3d gamma = a.R_wb.transpose() * b.R_wb;
  return std::max({(iv.preint.alpha - alpha).norm(), (iv.preint.beta - beta).norm(),
                   so3::log(gamma.transpose() * iv.preint.gamma.toRotationMatrix()).norm()});
}

}  // namespace

TEST_CASE("one interval per consecutive frame pair, ends at the frame times, matching ground truth",
          "[imu][interval_builder]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  const std::vector<ImuSample> s = imu_samples(tr, 1'900'000'000, 2'600'000'000);
  const std::vector<int64_t> f = frame_times();
  imu::ImuIntervalBuilder b;
  std::vector<PreintegratedInterval> out;
  for (int64_t t : f) b.add_frame(t);  // frames first: nothing can be emitted yet
  for (const ImuSample& x : s)
    for (auto& iv : b.add_imu(x)) out.push_back(std::move(iv));
  REQUIRE(out.size() == f.size() - 1);
  double worst = 0.0;
  for (size_t k = 0; k < out.size(); ++k) {
    CHECK(out[k].t_begin_ns == f[k]);
    CHECK(out[k].t_end_ns == f[k + 1]);
    CHECK(out[k].preint.samples.front().t_ns == f[k]);
    CHECK(out[k].preint.samples.back().t_ns == f[k + 1]);
    CHECK(out[k].preint.sum_dt == Approx(0.05).epsilon(1e-9));
    CHECK(out[k].num_raw_samples == 10);
    CHECK_FALSE(out[k].has_gap);
    CHECK(out[k].max_gap_ns == 5'000'000);
    worst = std::max(worst, max_delta_error(tr, out[k]));
  }
  // Linear interpolation of the end samples adds O(dt^2 * jerk) to the midpoint error; still far below noise.
  INFO("worst delta error vs truth " << worst);
  CHECK(worst < 1e-5);
  CHECK(b.stats().imu_rejected_out_of_order == 0);
}

TEST_CASE("the interleaving of IMU and frames does not change the intervals", "[imu][interval_builder]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  const std::vector<ImuSample> s = imu_samples(tr, 1'900'000'000, 2'600'000'000);
  const std::vector<int64_t> f = frame_times();
  // Reference: all IMU first, then the frames.
  imu::ImuIntervalBuilder ref;
  std::vector<PreintegratedInterval> a, c;
  for (const ImuSample& x : s) ref.add_imu(x);
  for (int64_t t : f)
    for (auto& iv : ref.add_frame(t)) a.push_back(std::move(iv));
  // Live-like: each frame arrives 3 IMU samples after its time.
  imu::ImuIntervalBuilder live;
  size_t fi = 0;
  for (const ImuSample& x : s) {
    for (auto& iv : live.add_imu(x)) c.push_back(std::move(iv));
    while (fi < f.size() && f[fi] + 15'000'000 <= x.t_ns)
      for (auto& iv : live.add_frame(f[fi++])) c.push_back(std::move(iv));
  }
  REQUIRE(a.size() == f.size() - 1);
  REQUIRE(c.size() == a.size());
  for (size_t k = 0; k < a.size(); ++k) {
    CHECK(a[k].t_begin_ns == c[k].t_begin_ns);
    CHECK((a[k].preint.alpha - c[k].preint.alpha).norm() == 0.0);
    CHECK((a[k].preint.covariance - c[k].preint.covariance).norm() == 0.0);
  }
}

TEST_CASE("out-of-order and duplicate IMU samples are rejected and counted", "[imu][interval_builder]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  const std::vector<ImuSample> s = imu_samples(tr, 1'900'000'000, 2'600'000'000);
  const std::vector<int64_t> f = frame_times();
  imu::ImuIntervalBuilder clean, dirty;
  std::vector<PreintegratedInterval> a, c;
  for (int64_t t : f) {
    clean.add_frame(t);
    dirty.add_frame(t);
  }
  for (size_t k = 0; k < s.size(); ++k) {
    for (auto& iv : clean.add_imu(s[k])) a.push_back(std::move(iv));
    for (auto& iv : dirty.add_imu(s[k])) c.push_back(std::move(iv));
    if (k == 30) {
      dirty.add_imu(s[k]);      // duplicate
      dirty.add_imu(s[k - 5]);  // late
      ImuSample odd = s[k];
      odd.t_ns -= 1;           // 1 ns before the last accepted one
      dirty.add_imu(odd);
    }
  }
  CHECK(dirty.stats().imu_rejected_out_of_order == 3);
  CHECK(clean.stats().imu_rejected_out_of_order == 0);
  REQUIRE(a.size() == c.size());
  for (size_t k = 0; k < a.size(); ++k) CHECK((a[k].preint.beta - c[k].preint.beta).norm() == 0.0);
  // Frames going backwards are rejected too.
  dirty.add_frame(f[3]);
  CHECK(dirty.stats().frames_rejected_out_of_order == 1);
}

TEST_CASE("an IMU gap above 3 periods is reported in its interval, not bridged silently",
          "[imu][interval_builder]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  const std::vector<ImuSample> s = imu_samples(tr, 1'900'000'000, 2'600'000'000);
  const std::vector<int64_t> f = frame_times();
  imu::ImuIntervalBuilder b;
  CHECK(b.gap_threshold_ns() == 15'000'000);
  for (int64_t t : f) b.add_frame(t);
  std::vector<PreintegratedInterval> out;
  for (const ImuSample& x : s) {
    // Drop 5 samples inside interval 2 ((2.1012, 2.1512] s): a 30 ms hole; drop 2 inside interval 5 (15 ms).
    if (x.t_ns > 2'110'000'000 && x.t_ns <= 2'135'000'000) continue;
    if (x.t_ns > 2'260'000'000 && x.t_ns <= 2'270'000'000) continue;
    for (auto& iv : b.add_imu(x)) out.push_back(std::move(iv));
  }
  REQUIRE(out.size() == f.size() - 1);
  for (size_t k = 0; k < out.size(); ++k) {
    INFO("interval " << k << " max gap " << out[k].max_gap_ns);
    CHECK(out[k].has_gap == (k == 2));
  }
  CHECK(out[2].max_gap_ns == 30'000'000);
  CHECK(out[5].max_gap_ns == 15'000'000);  // exactly 3 periods: at the threshold, not a gap
  CHECK(b.stats().intervals_with_gap == 1);
}

TEST_CASE("a frame with no IMU before it starts no interval and is counted", "[imu][interval_builder]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  const std::vector<ImuSample> s = imu_samples(tr, 2'030'000'000, 2'600'000'000);  // starts after the first frame
  const std::vector<int64_t> f = frame_times();
  imu::ImuIntervalBuilder b;
  std::vector<PreintegratedInterval> out;
  for (int64_t t : f) b.add_frame(t);
  for (const ImuSample& x : s)
    for (auto& iv : b.add_imu(x)) out.push_back(std::move(iv));
  CHECK(b.stats().frames_without_imu_before == 1);
  REQUIRE(out.size() == f.size() - 2);
  CHECK(out.front().t_begin_ns == f[1]);
}
