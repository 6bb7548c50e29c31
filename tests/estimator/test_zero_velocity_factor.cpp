// ZeroVelocityFactor: residual v / σ, Jacobian against numeric differences, biases untouched, and a
// solve that pulls a velocity to zero while leaving the biases where they were.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <vector>

#include <ceres/ceres.h>

#include "stages/estimator/factors/zero_velocity_factor.hpp"
#include "tests/estimator/factor_jacobian_check.hpp"

using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

TEST_CASE("ZeroVelocityFactor: residual is the whitened velocity, biases do not enter", "[estimator][factor]") {
  const ZeroVelocityFactor f(0.02);
  const std::vector<double> sb{0.1, -0.2, 0.04, 0.3, 0.2, -0.1, 0.01, 0.02, -0.03};
  const Evaluation e = evaluate(f, {sb});
  CHECK(e.residual.isApprox(Eigen::Vector3d(5.0, -10.0, 2.0)));
  CHECK(e.jacobians[0].rightCols(6).cwiseAbs().maxCoeff() == 0.0);
  require_jacobians_match_numeric(f, {sb}, {Block::Euclidean});
  CHECK_THROWS_AS(ZeroVelocityFactor(0.0), std::invalid_argument);
}

TEST_CASE("ZeroVelocityFactor: a solve brings the velocity to zero and keeps the biases", "[estimator][factor]") {
  std::vector<double> sb{0.5, -0.4, 0.2, 0.3, 0.2, -0.1, 0.01, 0.02, -0.03};
  const std::vector<double> start = sb;
  ZeroVelocityFactor f(0.01);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  problem.AddResidualBlock(&f, nullptr, sb.data());
  ceres::Solver::Options so;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  for (int k = 0; k < 3; ++k) CHECK(std::abs(sb[k]) < 1e-6);  // Levenberg-Marquardt stops a hair short of 0
  for (int k = 3; k < 9; ++k) CHECK(sb[k] == start[k]);
}
