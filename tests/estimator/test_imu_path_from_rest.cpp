// ImuPathFromRest and ImuStillVelocity (zupt_imu, issue 23) on exact IMU samples of a body that stands
// still, then drives off along x at 1 m/s² (level, no rotation): the path from the rest frame reproduces
// the drive-off, the departure test follows the configured accelerometer noise, and the IMU's velocity
// tells the drive-off from a standstill whatever the images say, also after a minute at rest with a
// small bias the window did not explain.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <vector>

#include "stages/estimator/imu_path_from_rest.hpp"
#include "stages/estimator/standstill_detector.hpp"
#include "stages/imu/imu_preintegration.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

constexpr double kG = 9.81;
constexpr int64_t kFrameNs = 50'000'000;  // 20 Hz frames
constexpr int kSamplesPerFrame = 10;      // 200 Hz IMU

/// The preintegration of frame interval [k, k + 1) for a level body accelerating at `a` along x; the
/// accelerometer reads `a + drift` (a bias the window did not estimate).
std::unique_ptr<imu::ImuPreintegration> interval(int k, double a, double drift = 0.0) {
  auto sample = [a, drift](int64_t t_ns) {
    ImuSample s;
    s.t_ns = t_ns;
    s.acc = Eigen::Vector3d(a + drift, 0, kG);  // specific force: acceleration minus gravity (0, 0, -g)
    return s;
  };
  const int64_t t0 = k * kFrameNs;
  auto pre = std::make_unique<imu::ImuPreintegration>(sample(t0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                      imu::ImuNoiseParams{});
  for (int i = 1; i <= kSamplesPerFrame; ++i) pre->integrate(sample(t0 + i * kFrameNs / kSamplesPerFrame));
  return pre;
}

}  // namespace

TEST_CASE("the IMU-only path from a rest frame reproduces a drive-off", "[zupt_imu]") {
  ImuPathFromRest path;
  REQUIRE(path.empty());
  path.extend(kFrameNs, *interval(0, 1.0), kG);  // no anchor: nothing to extend
  REQUIRE(path.empty());

  const Eigen::Vector3d p0(2, -1, 1.5);
  path.anchor(0, p0, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
              Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  for (int k = 0; k < 20; ++k) path.extend((k + 1) * kFrameNs, *interval(k, 1.0), kG);
  REQUIRE(path.anchor_t_ns() == 0);
  REQUIRE(path.after_anchor(0) == nullptr);  // the anchor itself is judged on its solved state
  REQUIRE(path.after_anchor(kFrameNs / 2) == nullptr);
  for (int k = 1; k <= 20; ++k) {
    const double t = k * 0.05;
    const ImuPathFromRest::Pose* pose = path.after_anchor(k * kFrameNs);
    REQUIRE(pose != nullptr);
    CHECK((pose->p - (p0 + Eigen::Vector3d(0.5 * t * t, 0, 0))).norm() < 1e-9);
    CHECK(pose->q.angularDistance(Eigen::Quaterniond::Identity()) < 1e-12);
  }

  // Departure: 3 σ of the configured noise integrated twice, σ = acc_n T^1.5 / √3; at T = 1 s and acc_n = 0.1
  // that is 0.173 m.
  const Eigen::Vector3d on_path = path.after_anchor(20 * kFrameNs)->p;
  CHECK_FALSE(path.departed(20 * kFrameNs, on_path + Eigen::Vector3d(0.15, 0, 0), 0.1));
  CHECK(path.departed(20 * kFrameNs, on_path + Eigen::Vector3d(0, 0.2, 0), 0.1));
  CHECK_FALSE(path.departed(21 * kFrameNs, on_path, 0.1));  // not on the path: never departed


  // Started from 0.05 m/s where the solve had 0 (the IMU's velocity at the last still frame against the
  // zero-velocity factor's): 0.05 m of the gap at T = 1 s is that difference, not a departure.
  path.anchor(0, p0, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d::Zero(),
              Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  for (int k = 0; k < 20; ++k) path.extend((k + 1) * kFrameNs, *interval(k, 1.0), kG);
  const Eigen::Vector3d faster = path.after_anchor(20 * kFrameNs)->p;
  CHECK((faster - on_path).norm() == Approx(0.05).epsilon(1e-9));
  // The threshold is now 0.05 + 0.173 m.
  CHECK_FALSE(path.departed(20 * kFrameNs, faster + Eigen::Vector3d(0.2, 0, 0), 0.1));
  CHECK(path.departed(20 * kFrameNs, faster + Eigen::Vector3d(0.25, 0, 0), 0.1));

  path.clear();
  REQUIRE(path.empty());
}

TEST_CASE("the IMU's velocity tells a drive-off from a standstill", "[zupt_imu]") {
  const Eigen::Quaterniond level = Eigen::Quaterniond::Identity();
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  ImuStillVelocity still;
  for (int k = 0; k < 200; ++k) still.add(*interval(k, 0.0), level, zero, zero, kG);  // 10 s at rest
  CHECK(still.velocity().norm() < 1e-9);

  // A minute at rest with 0.0125 m/s² the biases do not explain (what a minute-long stop showed): forgotten
  // over 1 s the integral stays near 0.0125 m/s, where summed it would reach 0.75 m/s.
  for (int k = 0; k < 1200; ++k) still.add(*interval(k, 0.0, 0.0125), level, zero, zero, kG);
  CHECK(still.velocity().norm() < 0.015);
  CHECK(still.velocity().norm() > 0.01);

  // Driving off at 1 m/s²: past 0.1 m/s (zupt_max_velocity) within 0.15 s, whatever the images show.
  still.restart(zero);
  for (int k = 0; k < 3; ++k) still.add(*interval(k, 1.0), level, zero, zero, kG);
  CHECK(still.velocity().x() > 0.1);
  CHECK(still.velocity().x() < 0.15);

  // The biases are the ones the still run started with: a later bias that explains the drive-off (what the
  // solve does while the zero-velocity factor holds v = 0) does not hide it.
  still.restart(zero);
  still.add(*interval(0, 0.0), level, zero, zero, kG);
  for (int k = 1; k < 4; ++k) still.add(*interval(k, 1.0), level, Eigen::Vector3d(1.0, 0, 0), zero, kG);
  CHECK(still.velocity().x() > 0.1);
  CHECK(still.ba().norm() == 0.0);

  // A moving solve restarts the integral from its velocity, which is then forgotten like the rest.
  still.restart(Eigen::Vector3d(3, 0, 0));
  still.add(*interval(0, 0.0), level, zero, zero, kG);
  CHECK(still.velocity().x() == Approx(3 * std::exp(-0.05)).epsilon(1e-9));
}
