// estimate_gyro_bias: recovers a known gyroscope bias from true rotations and preintegrations built
// with zero bias (VINS-Mono §V-B-1).
#include <catch2/catch.hpp>

#include "stages/common/so3.hpp"
#include "stages/estimator/initialization/gyro_bias_estimator.hpp"
#include "tests/estimator/test_initialization_scenario.hpp"

using namespace dynavins;
using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

namespace {
std::vector<Eigen::Matrix3d> true_rotations(const Scenario& s) {
  std::vector<Eigen::Matrix3d> R;
  for (const auto& st : s.truth) R.push_back(st.R_wb);
  return R;
}
}  // namespace

TEST_CASE("gyro bias from true rotations with a noise-free IMU", "[estimator][initialization]") {
  ScenarioOptions o;
  o.gyro_bias = Eigen::Vector3d(0.02, -0.015, 0.03);
  const Scenario s = make_scenario(o);
  const Eigen::Vector3d bg = estimate_gyro_bias(true_rotations(s), s.preint_pointers());
  INFO("estimated " << bg.transpose() << " true " << o.gyro_bias.transpose());
  CHECK((bg - o.gyro_bias).norm() < 1e-3);

  // After repropagation with it, the preintegrated rotations match the truth.
  for (int k = 0; k + 1 < s.frames(); ++k) {
    s.preints[k]->repropagate(Eigen::Vector3d::Zero(), bg);
    const Eigen::Matrix3d R_rel = s.truth[k].R_wb.transpose() * s.truth[k + 1].R_wb;
    CHECK(so3::log(s.preints[k]->delta_q().toRotationMatrix().transpose() * R_rel).norm() < 1e-4);
  }
}

TEST_CASE("gyro bias from true rotations with a noisy IMU", "[estimator][initialization]") {
  ScenarioOptions o;
  o.imu_noise = true;
  o.gyro_bias = Eigen::Vector3d(-0.01, 0.025, 0.015);
  const Scenario s = make_scenario(o);
  const Eigen::Vector3d bg = estimate_gyro_bias(true_rotations(s), s.preint_pointers());
  INFO("estimated " << bg.transpose() << " true " << o.gyro_bias.transpose());
  // EuRoC-grade gyro white noise over 1 s contributes ~2e-4 rad/s.
  CHECK((bg - o.gyro_bias).norm() < 1e-3);
}

TEST_CASE("gyro bias rejects mismatched inputs", "[estimator][initialization]") {
  const Scenario s = make_scenario();
  std::vector<Eigen::Matrix3d> R = true_rotations(s);
  R.pop_back();
  CHECK_THROWS_AS(estimate_gyro_bias(R, s.preint_pointers()), std::invalid_argument);
}
