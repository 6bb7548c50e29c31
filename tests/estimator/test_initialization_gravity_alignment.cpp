// gravity_aligned_rotation / rotation_aligning_gravity: gravity lands on the world z axis with zero yaw,
// for random tilts including upside-down bodies.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "stages/common/so3.hpp"
#include "stages/estimator/initialization/gravity_alignment.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

TEST_CASE("gravity_aligned_rotation recovers random tilts with zero yaw", "[estimator][initialization]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), tilt(-1.4, 1.4);
  for (int i = 0; i < 200; ++i) {
    const double pitch = tilt(rng), roll = angle(rng), yaw = angle(rng);
    const Eigen::Matrix3d R_true = so3::from_yaw_pitch_roll(yaw, pitch, roll);
    const double g = 9.81 + 0.1 * tilt(rng);
    const Eigen::Vector3d f = R_true.transpose() * Eigen::Vector3d(0, 0, g);  // specific force at rest
    const Eigen::Matrix3d R = gravity_aligned_rotation(f);
    INFO("yaw " << yaw << " pitch " << pitch << " roll " << roll);
    CHECK((R * f - Eigen::Vector3d(0, 0, f.norm())).norm() < 1e-9);
    CHECK(std::abs(yaw_of(R)) < 1e-9);
    CHECK(std::abs(R.determinant() - 1.0) < 1e-12);
    // Given the gravity direction, the zero-yaw rotation is unique: the truth without its yaw.
    const Eigen::Matrix3d R_expected = so3::from_yaw_pitch_roll(0.0, pitch, roll);
    CHECK(so3::log(R.transpose() * R_expected).norm() < 1e-9);
  }
}

TEST_CASE("gravity_aligned_rotation handles a body upside down", "[estimator][initialization]") {
  const Eigen::Vector3d f(0.0, 0.0, -9.81);  // z axis pointing down
  const Eigen::Matrix3d R = gravity_aligned_rotation(f);
  CHECK((R * f - Eigen::Vector3d(0, 0, 9.81)).norm() < 1e-9);
  CHECK(std::abs(yaw_of(R)) < 1e-9);
}

TEST_CASE("rotation_aligning_gravity puts a gravity vector on -z", "[estimator][initialization]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> a(-M_PI, M_PI);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d R_c0w = so3::from_yaw_pitch_roll(a(rng), a(rng) / 2.2, a(rng));
    const Eigen::Vector3d g_c0 = R_c0w * Eigen::Vector3d(0, 0, -9.81);
    const Eigen::Matrix3d R = rotation_aligning_gravity(g_c0);
    CHECK((R * g_c0 - Eigen::Vector3d(0, 0, -9.81)).norm() < 1e-9);
    CHECK(std::abs(yaw_of(R)) < 1e-9);
  }
}
