// trajectory_metrics: numpy-compatible statistics, ATE and RPE on hand-checkable data.
#include "eval/trajectory_metrics.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace dynavins::eval;

TEST_CASE("error_stats matches numpy definitions", "[eval][metrics]") {
  const ErrorStats s = error_stats({3.0, 1.0, 4.0, 2.0});
  CHECK(s.count == 4);
  CHECK(s.mean == Approx(2.5));
  CHECK(s.median == Approx(2.5));  // even count: mean of the middle two
  CHECK(s.min == 1.0);
  CHECK(s.max == 4.0);
  CHECK(s.sse == Approx(30.0));
  CHECK(s.rmse == Approx(std::sqrt(7.5)));
  CHECK(s.std == Approx(std::sqrt(1.25)));  // population std, ddof = 0
  CHECK(error_stats({5.0, 1.0, 2.0}).median == 2.0);
  CHECK_THROWS_AS(error_stats({}), std::invalid_argument);
}

TEST_CASE("ate_translation_errors is the per-pair distance", "[eval][metrics]") {
  const std::vector<Eigen::Vector3d> gt = {{0, 0, 0}, {1, 0, 0}};
  const std::vector<Eigen::Vector3d> est = {{0, 3, 4}, {1, 0, 0}};
  const std::vector<double> e = ate_translation_errors(gt, est);
  REQUIRE(e.size() == 2);
  CHECK(e[0] == Approx(5.0));
  CHECK(e[1] == 0.0);
  CHECK_THROWS_AS(ate_translation_errors(gt, {est[0]}), std::invalid_argument);
}

TEST_CASE("rpe_translation_errors measures relative motion error in the body frame", "[eval][metrics]") {
  // Ground truth drives 1 m along its own x per step after turning 90 degrees; the estimate
  // drives 1.1 m instead, so each relative step is off by 0.1 m whatever the world frame.
  std::vector<Eigen::Isometry3d> gt, est;
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity(), e = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d step_g = Eigen::Isometry3d::Identity(), step_e = Eigen::Isometry3d::Identity();
  step_g.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  step_e.linear() = step_g.linear();
  step_g.translation() = Eigen::Vector3d(1.0, 0, 0);
  step_e.translation() = Eigen::Vector3d(1.1, 0, 0);
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(5, -2, 1);
  for (int i = 0; i < 7; ++i) {
    gt.push_back(g);
    est.push_back(offset * e);  // a rigid offset must not change RPE
    g = g * step_g;
    e = e * step_e;
  }
  const std::vector<double> d1 = rpe_translation_errors(gt, est, 1);
  REQUIRE(d1.size() == 6);
  for (double x : d1) CHECK(x == Approx(0.1).margin(1e-12));
  // delta 3 uses pairs (0,3), (3,6) only.
  CHECK(rpe_translation_errors(gt, est, 3).size() == 2);
  CHECK(rpe_translation_errors(gt, est, 6).size() == 1);
  CHECK_THROWS_AS(rpe_translation_errors(gt, est, 7), std::invalid_argument);
  CHECK_THROWS_AS(rpe_translation_errors(gt, est, 0), std::invalid_argument);
  est.pop_back();
  CHECK_THROWS_AS(rpe_translation_errors(gt, est, 1), std::invalid_argument);
}
