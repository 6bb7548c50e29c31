// WindowGauge: after a solve moved the whole window (gauge drift), restore() gives the oldest frame back
// its position and yaw, keeps its solved roll and pitch, and leaves the window's relative geometry
// (relative poses, body-frame velocities) untouched.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "stages/common/so3.hpp"
#include "stages/estimator/initialization/gravity_alignment.hpp"
#include "stages/estimator/window_gauge.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

constexpr int kWindow = 10;

WindowState random_window(uint64_t seed, double pitch0 = 0.1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  WindowState s(kWindow);
  for (int k = 0; k <= kWindow; ++k) {
    s.p(k) = Eigen::Vector3d(30.0 + 3.0 * k + u(rng), -5.0 + u(rng), 2.0 + 0.2 * u(rng));
    const double pitch = k == 0 ? pitch0 : 0.1 * u(rng);
    s.q(k) = Eigen::Quaterniond(so3::from_yaw_pitch_roll(0.7 + 0.2 * u(rng), pitch, 0.1 * u(rng)));
    s.v(k) = Eigen::Vector3d(3.0 + u(rng), u(rng), 0.1 * u(rng));
  }
  return s;
}

// A solve that, besides its real work, moved the whole window: rotation R about an arbitrary axis and a
// translation t.
void move_window(WindowState& s, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  for (int k = 0; k <= kWindow; ++k) {
    s.p(k) = R * s.p(k) + t;
    s.q(k) = (Eigen::Quaterniond(R) * s.q(k)).normalized();
    s.v(k) = R * s.v(k);
  }
}

double angle_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle() * 180.0 / M_PI;
}

Eigen::Matrix3d roll_pitch_of(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(-yaw_of(R), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R;
}

}  // namespace

TEST_CASE("window gauge restores the oldest frame's position and yaw, keeps roll, pitch and the shape",
          "[estimator]") {
  const uint64_t seed = GENERATE(1, 2, 3);
  WindowState s = random_window(seed);
  const WindowGauge gauge = WindowGauge::of(s);
  const Eigen::Vector3d p0 = s.p(0);
  const double yaw0 = yaw_of(s.q(0).toRotationMatrix());

  // Drift: 5 deg of yaw, 0.5 deg of roll (a real correction the solve made), 2 m of translation.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(5.0 * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  move_window(s, R, Eigen::Vector3d(2.0, -1.0, 0.5));
  WindowState moved = [&] { WindowState c(kWindow); c.pose = s.pose; c.speed_bias = s.speed_bias; return c; }();
  gauge.restore(s, kWindow);

  CHECK((s.p(0) - p0).norm() < 1e-9);
  CHECK(std::abs(yaw_of(s.q(0).toRotationMatrix()) - yaw0) < 1e-9);
  // Roll and pitch stay as solved (gravity observes them).
  CHECK((roll_pitch_of(s.q(0).toRotationMatrix()) - roll_pitch_of(moved.q(0).toRotationMatrix())).norm() < 1e-9);
  for (int k = 1; k <= kWindow; ++k) {
    // Relative pose to the oldest frame and body-frame velocity: unchanged.
    const Eigen::Quaterniond rel_before = moved.q(0).conjugate() * moved.q(k);
    const Eigen::Quaterniond rel_after = s.q(0).conjugate() * s.q(k);
    CHECK(angle_deg(rel_before, rel_after) < 1e-7);
    const Eigen::Vector3d d_before = moved.q(0).conjugate() * (moved.p(k) - moved.p(0));
    const Eigen::Vector3d d_after = s.q(0).conjugate() * (s.p(k) - s.p(0));
    CHECK((d_before - d_after).norm() < 1e-9);
    const Eigen::Vector3d v_before = moved.q(k).conjugate() * Eigen::Vector3d(moved.v(k));
    const Eigen::Vector3d v_after = s.q(k).conjugate() * Eigen::Vector3d(s.v(k));
    CHECK((v_before - v_after).norm() < 1e-9);
  }
}

TEST_CASE("window gauge undoes the whole rotation when the oldest frame looks straight up or down",
          "[estimator]") {
  WindowState s = random_window(4, M_PI / 2);  // yaw is undefined at pitch 90 deg
  const WindowGauge gauge = WindowGauge::of(s);
  const Eigen::Quaterniond q0 = s.q(0);
  const Eigen::Vector3d p0 = s.p(0);
  move_window(s, Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix(),
             Eigen::Vector3d(1, 1, 1));
  gauge.restore(s, kWindow);
  CHECK(angle_deg(s.q(0), q0) < 1e-7);
  CHECK((s.p(0) - p0).norm() < 1e-9);
}
