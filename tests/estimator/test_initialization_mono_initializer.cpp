// initialize_mono: poses, velocities, bias and depths vs the truth in the gravity-aligned, zero-yaw,
// first-body-origin world; pure rotation and a missing preintegration fail with a reason.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "stages/estimator/initialization/gravity_alignment.hpp"
#include "stages/estimator/initialization/mono_initializer.hpp"
#include "tests/estimator/test_initialization_scenario.hpp"

using namespace dynavins;
using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

namespace {

struct InitErrors {
  double rot_deg = 0.0, pos_m = 0.0, vel_mps = 0.0, depth_rel = 0.0, bg = 0.0;
};

InitErrors compare(const Scenario& s, const MonoInitResult& r, const Eigen::Vector3d& bg_true) {
  // The truth in the initializer's convention: yaw of body 0 removed, origin at body 0.
  const Eigen::Matrix3d R_align =
      Eigen::AngleAxisd(-yaw_of(s.truth[0].R_wb), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  InitErrors e;
  for (int k = 0; k < s.frames(); ++k) {
    e.rot_deg = std::max(e.rot_deg, angle_deg((R_align * s.truth[k].R_wb).transpose() * r.R_wb[k]));
    e.pos_m = std::max(e.pos_m, (R_align * (s.truth[k].p_w - s.truth[0].p_w) - r.p_wb[k]).norm());
    e.vel_mps = std::max(e.vel_mps, (R_align * s.truth[k].v_w - r.v_wb[k]).norm());
  }
  for (const auto& [id, d] : r.depths) {
    const double z = (s.R_wc(d.anchor_frame).transpose() * (s.landmarks_w.at(id) - s.p_wc(d.anchor_frame))).z();
    e.depth_rel = std::max(e.depth_rel, std::abs(d.depth - z) / z);
  }
  e.bg = (r.bg - bg_true).norm();
  return e;
}

}  // namespace

TEST_CASE("mono initializer on noise-free data matches the truth", "[estimator][initialization]") {
  ScenarioOptions o;
  const Scenario s = make_scenario(o);
  const MonoInitResult r = initialize_mono(s.window(), s.R_bc, s.p_bc);
  INFO(r.reason);
  REQUIRE(r.success);
  REQUIRE(static_cast<int>(r.p_wb.size()) == s.frames());
  const InitErrors e = compare(s, r, o.gyro_bias);
  INFO("rot " << e.rot_deg << " deg, pos " << e.pos_m << " m, vel " << e.vel_mps << " m/s, depth " << e.depth_rel
              << ", bg " << e.bg << ", scale " << r.scale << ", l " << r.sfm_reference_frame);
  CHECK(r.p_wb[0].norm() < 1e-12);
  CHECK(std::abs(yaw_of(r.R_wb[0])) < 1e-9);
  CHECK(e.bg < 1e-3);
  CHECK(e.rot_deg < 0.1);
  CHECK(e.pos_m < 0.02);
  CHECK(e.vel_mps < 0.02);
  CHECK(r.depths.size() > 150);
  CHECK(e.depth_rel < 0.01);
  // The preintegrations now carry the estimated bias.
  for (const auto& p : s.preints) CHECK((p->linearized_bg() - r.bg).norm() < 1e-12);
}

TEST_CASE("mono initializer with 0.5 px and EuRoC-grade IMU noise", "[estimator][initialization]") {
  // Several noise draws, so the margins are not one lucky seed.
  const uint64_t seed = GENERATE(7, 8, 9, 10, 11);
  ScenarioOptions o;
  o.pixel_noise_px = 0.5;
  o.imu_noise = true;
  o.seed = seed;
  const Scenario s = make_scenario(o);
  const MonoInitResult r = initialize_mono(s.window(), s.R_bc, s.p_bc);
  INFO("seed " << seed << ": " << r.reason);
  REQUIRE(r.success);
  const InitErrors e = compare(s, r, o.gyro_bias);
  INFO("rot " << e.rot_deg << " deg, pos " << e.pos_m << " m, vel " << e.vel_mps << " m/s, depth " << e.depth_rel
              << ", bg " << e.bg << ", scale " << r.scale << " (rel std " << r.scale_relative_std << "), rms "
              << r.sfm_rms_reprojection_px << " px");
  // Measured over these seeds: bg <= 7.5e-4 rad/s, rot <= 0.19 deg, pos <= 1.4 cm, vel <= 0.025 m/s,
  // depth <= 6 % (worst feature).
  CHECK(e.bg < 2e-3);
  CHECK(e.rot_deg < 0.5);
  CHECK(e.pos_m < 0.04);
  CHECK(e.vel_mps < 0.06);
  CHECK(e.depth_rel < 0.15);
}

TEST_CASE("mono initializer fails cleanly on a pure rotation", "[estimator][initialization]") {
  ScenarioOptions o;
  o.pure_rotation = true;
  const Scenario s = make_scenario(o);
  const MonoInitResult r = initialize_mono(s.window(), s.R_bc, s.p_bc);
  INFO(r.reason);
  CHECK_FALSE(r.success);
  CHECK_FALSE(r.reason.empty());
}

TEST_CASE("mono initializer keeps 64-bit feature ids apart", "[estimator][initialization]") {
  // The tracker numbers features with int64_t; ids that agree in their low 32 bits are distinct tracks.
  ScenarioOptions o;
  o.wide_ids = true;
  const Scenario s = make_scenario(o);
  const MonoInitResult r = initialize_mono(s.window(), s.R_bc, s.p_bc);
  INFO(r.reason);
  REQUIRE(r.success);
  CHECK(r.depths.size() > 150);
  for (const auto& [id, d] : r.depths) CHECK(s.landmarks_w.count(id) == 1);
  const InitErrors e = compare(s, r, o.gyro_bias);
  CHECK(e.pos_m < 1e-3);
  CHECK(e.depth_rel < 1e-3);
}

namespace {
// The initializer on a window whose motion leaves the scale unobservable (0.5 px, EuRoC-grade IMU).
MonoInitResult initialize_unobservable(bool constant_acceleration, uint64_t seed) {
  ScenarioOptions o;
  o.constant_velocity = !constant_acceleration;
  o.constant_acceleration = constant_acceleration;
  o.pixel_noise_px = 0.5;
  o.imu_noise = true;
  o.seed = seed;
  const Scenario s = make_scenario(o);
  return initialize_mono(s.window(), s.R_bc, s.p_bc);
}
}  // namespace

TEST_CASE("mono initializer refuses a scale that constant velocity leaves unobservable",
          "[estimator][initialization]") {
  // Without acceleration the IMU cannot tell the scale (any s with v = s * visual velocity fits); the
  // noise then picks an arbitrary scale, which must be rejected rather than start the estimator.
  const uint64_t seed = GENERATE(7, 8, 9);
  const MonoInitResult r = initialize_unobservable(false, seed);
  INFO("seed " << seed << ": " << r.reason << " scale " << r.scale);
  // Without the scale-uncertainty test seeds 7 and 8 "succeed" with arbitrary scales;
  // seed 9 already fails the free-gravity test.
  CHECK_FALSE(r.success);
  CHECK_FALSE(r.reason.empty());
}

TEST_CASE("mono initializer refuses a scale that constant acceleration leaves unobservable",
          "[estimator][initialization]") {
  // A constant acceleration is indistinguishable from a tilted, stronger gravity: the free-gravity solve
  // fits any scale (the lever arm aside). The window's excitation tells, whatever the scale's fit says.
  const uint64_t seed = GENERATE(7, 8, 9);
  const MonoInitResult r = initialize_unobservable(true, seed);
  INFO("seed " << seed << ": " << r.reason << " scale " << r.scale);
  CHECK_FALSE(r.success);
  CHECK_THAT(r.reason, Catch::Contains("excitation"));
}

TEST_CASE("mono initializer reports a missing preintegration", "[estimator][initialization]") {
  const Scenario s = make_scenario();
  std::vector<InitWindowFrame> w = s.window();
  w[4].preint = nullptr;
  const MonoInitResult r = initialize_mono(w, s.R_bc, s.p_bc);
  CHECK_FALSE(r.success);
  CHECK(r.reason.find("preintegration") != std::string::npos);
}
