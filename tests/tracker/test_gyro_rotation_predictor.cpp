// GyroRotationPredictor: the integrated gyro rotation against closed forms (constant and linearly
// growing rate about a fixed axis), bias removal, the camera-IMU conjugation against an independently
// composed camera orientation, and no prediction whenever the samples do not cover the interval.
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "stages/common/so3.hpp"
#include "stages/tracker/gyro_rotation_predictor.hpp"

using namespace dynavins;

namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kPeriod = 5 * kMs;  // 200 Hz
constexpr int64_t kMaxGap = 3 * kPeriod;

/// 200 Hz samples on [from, to] with angular rate rate(t) [rad/s], t in seconds.
template <typename Rate>
std::vector<ImuSample> samples(int64_t from, int64_t to, Rate rate) {
  std::vector<ImuSample> v;
  for (int64_t t = from; t <= to; t += kPeriod) {
    ImuSample s;
    s.t_ns = t;
    s.gyr = rate(static_cast<double>(t) * 1e-9);
    s.acc = Eigen::Vector3d(0, 0, 9.81);
    v.push_back(s);
  }
  return v;
}

double angle_between(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) { return so3::log(A.transpose() * B).norm(); }

const Eigen::Vector3d kRate(0.3, -0.8, 1.1);  // rad/s, about 80 deg/s: a quick turn
// Frame times off the IMU grid, so both ends are interpolated.
const int64_t kT0 = 1'000 * kMs + 1'234'567, kT1 = kT0 + 50 * kMs;

}  // namespace

TEST_CASE("tracker::GyroRotationPredictor integrates a constant rate exactly", "[tracker][gyro]") {
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), kMaxGap);
  const auto imu = samples(990 * kMs, 1'060 * kMs, [](double) { return kRate; });
  const auto R = p.predict_body(imu, kT0, kT1);
  REQUIRE(R);
  const Eigen::Matrix3d expected = so3::exp(kRate * (static_cast<double>(kT1 - kT0) * 1e-9));
  CHECK(angle_between(*R, expected) < 1e-12);
  // With the identity extrinsic the camera turns like the body.
  CHECK(angle_between(*p.predict(imu, kT0, kT1), expected) < 1e-12);
}

TEST_CASE("tracker::GyroRotationPredictor cuts the samples at the frame times", "[tracker][gyro]") {
  // Rate growing linearly about a fixed axis: the rotations commute, the angle is the integral of the
  // rate, and the midpoint rule on linearly interpolated ends is exact; a wrong cut at t0 or t1 is not.
  const Eigen::Vector3d axis = kRate.normalized();
  auto rate = [&](double t) -> Eigen::Vector3d { return (2.0 + 3.0 * (t - 1.0)) * axis; };
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), kMaxGap);
  const auto imu = samples(990 * kMs, 1'060 * kMs, rate);
  const double a = static_cast<double>(kT0) * 1e-9, b = static_cast<double>(kT1) * 1e-9;
  const double angle = 2.0 * (b - a) + 1.5 * ((b - 1.0) * (b - 1.0) - (a - 1.0) * (a - 1.0));
  const auto R = p.predict_body(imu, kT0, kT1);
  REQUIRE(R);
  CHECK(angle_between(*R, so3::exp(angle * axis)) < 1e-12);
  // Frame times on sample times work the same way.
  const auto R_grid = p.predict_body(imu, 1'000 * kMs, 1'050 * kMs);
  REQUIRE(R_grid);
  CHECK(angle_between(*R_grid, so3::exp((2.0 * 0.05 + 1.5 * 0.05 * 0.05) * axis)) < 1e-12);
}

TEST_CASE("tracker::GyroRotationPredictor subtracts the gyro bias", "[tracker][gyro]") {
  const Eigen::Vector3d bias(0.02, -0.01, 0.015);
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), kMaxGap);
  const auto imu = samples(990 * kMs, 1'060 * kMs, [&](double) -> Eigen::Vector3d { return kRate + bias; });
  const Eigen::Matrix3d truth = so3::exp(kRate * (static_cast<double>(kT1 - kT0) * 1e-9));
  const auto with = p.predict_body(imu, kT0, kT1, bias);
  const auto without = p.predict_body(imu, kT0, kT1);
  REQUIRE(with);
  REQUIRE(without);
  CHECK(angle_between(*with, truth) < 1e-12);
  // Uncorrected, the bias turns the prediction by about |bias| * dt.
  CHECK(angle_between(*without, truth) == Approx(bias.norm() * 0.05).epsilon(0.05));
}

TEST_CASE("tracker::GyroRotationPredictor turns the body rotation into cam0's with the extrinsic", "[tracker][gyro]") {
  // A camera mounted like EuRoC's cam0 (optical axis sideways from the IMU) plus an odd tilt.
  Eigen::Isometry3d body_T_cam0 = Eigen::Isometry3d::Identity();
  body_T_cam0.linear() = so3::exp(Eigen::Vector3d(0.1, -0.05, 1.55)) * so3::exp(Eigen::Vector3d(0.3, 0, 0));
  body_T_cam0.translation() = Eigen::Vector3d(-0.02, -0.06, 0.01);
  const tracker::GyroRotationPredictor p(body_T_cam0, kMaxGap);
  const auto imu = samples(990 * kMs, 1'060 * kMs, [](double) { return kRate; });
  const auto R = p.predict(imu, kT0, kT1);
  REQUIRE(R);

  // Composed independently: the body turns at a constant rate, R_wb(t) = Exp(rate t); the camera is
  // R_wc = R_wb R_bc; the relative rotation is R_wc(t0)^T R_wc(t1).
  const Eigen::Matrix3d R_bc = body_T_cam0.linear();
  auto R_wc = [&](int64_t t) -> Eigen::Matrix3d { return so3::exp(kRate * (static_cast<double>(t) * 1e-9)) * R_bc; };
  const Eigen::Matrix3d expected = R_wc(kT0).transpose() * R_wc(kT1);
  CHECK(angle_between(*R, expected) < 1e-9);
  // The camera's rotation axis is the body's expressed in the camera: R_bc^T * rate.
  const Eigen::Vector3d axis_cam = so3::log(*R).normalized();
  CHECK((axis_cam - (R_bc.transpose() * kRate).normalized()).norm() < 1e-9);
  // And it is not the body rotation itself (the conjugation matters for this mount).
  CHECK(angle_between(*R, *p.predict_body(imu, kT0, kT1)) > 0.01);
}

TEST_CASE("tracker::GyroRotationPredictor predicts nothing when the samples do not cover the interval", "[tracker][gyro]") {
  const tracker::GyroRotationPredictor p(Eigen::Isometry3d::Identity(), kMaxGap);
  const auto imu = samples(990 * kMs, 1'060 * kMs, [](double) { return kRate; });
  REQUIRE(p.predict_body(imu, kT0, kT1));

  SECTION("no sample at or before the previous frame (first frame, dropped frame)") {
    CHECK_FALSE(p.predict_body(samples(kT0 + 1, 1'060 * kMs, [](double) { return kRate; }), kT0, kT1));
  }
  SECTION("no sample at or after the current frame yet") {
    CHECK_FALSE(p.predict_body(samples(990 * kMs, kT1 - 1, [](double) { return kRate; }), kT0, kT1));
  }
  SECTION("an IMU outage inside the interval") {
    std::vector<ImuSample> gap;
    for (const ImuSample& s : imu)
      if (s.t_ns < 1'020 * kMs || s.t_ns > 1'035 * kMs) gap.push_back(s);  // 25 ms between two samples
    CHECK_FALSE(p.predict_body(gap, kT0, kT1));
    // One lost sample (10 ms spacing) is jitter, below the 15 ms limit.
    std::vector<ImuSample> jitter;
    for (const ImuSample& s : imu)
      if (s.t_ns != 1'020 * kMs) jitter.push_back(s);
    CHECK(p.predict_body(jitter, kT0, kT1));
  }
  SECTION("an outage straddling a frame time") {
    std::vector<ImuSample> gap;
    for (const ImuSample& s : imu)
      if (s.t_ns < 990 * kMs + 1 || s.t_ns > 1'005 * kMs) gap.push_back(s);  // only 990 ms, then 1010 ms
    CHECK_FALSE(p.predict_body(gap, kT0, kT1));
  }
  SECTION("an outage outside the interval does not matter") {
    std::vector<ImuSample> before{imu.front()};
    before.front().t_ns = 900 * kMs;  // 95 ms before the next sample, both before the previous frame
    before.insert(before.end(), imu.begin() + 1, imu.end());
    CHECK(p.predict_body(before, kT0, kT1));
  }
  SECTION("empty, single sample, or not a forward interval") {
    CHECK_FALSE(p.predict_body({}, kT0, kT1));
    CHECK_FALSE(p.predict_body({imu.front()}, kT0, kT1));
    CHECK_FALSE(p.predict_body(imu, kT1, kT0));
    CHECK_FALSE(p.predict_body(imu, kT0, kT0));
  }
  SECTION("repeated or out-of-order samples are skipped, not integrated backwards") {
    std::vector<ImuSample> messy;
    for (const ImuSample& s : imu) {
      messy.push_back(s);
      if (s.t_ns == 1'020 * kMs) {
        ImuSample back = s;
        back.t_ns -= 3 * kMs;
        back.gyr = Eigen::Vector3d(50, 50, 50);
        messy.push_back(s);     // repeated
        messy.push_back(back);  // earlier than its predecessor
      }
    }
    const auto R = p.predict_body(messy, kT0, kT1);
    REQUIRE(R);
    CHECK(angle_between(*R, *p.predict_body(imu, kT0, kT1)) < 1e-12);
  }
  CHECK_THROWS_AS(tracker::GyroRotationPredictor(Eigen::Isometry3d::Identity(), 0), std::invalid_argument);
}
