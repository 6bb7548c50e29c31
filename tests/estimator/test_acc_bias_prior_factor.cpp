// AccBiasPriorFactor: residual b_a / σ, Jacobian against numeric differences, velocity and gyroscope
// bias untouched.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <vector>

#include "stages/estimator/factors/acc_bias_prior_factor.hpp"
#include "tests/estimator/factor_jacobian_check.hpp"

using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

TEST_CASE("AccBiasPriorFactor: residual is the whitened accelerometer bias, nothing else enters", "[estimator][factor]") {
  const AccBiasPriorFactor f(0.1);
  const std::vector<double> sb{0.5, -0.4, 0.2, 0.03, -0.12, 0.05, 0.01, 0.02, -0.03};
  const Evaluation e = evaluate(f, {sb});
  CHECK(e.residual.isApprox(Eigen::Vector3d(0.3, -1.2, 0.5)));
  CHECK(e.jacobians[0].leftCols(3).cwiseAbs().maxCoeff() == 0.0);
  CHECK(e.jacobians[0].rightCols(3).cwiseAbs().maxCoeff() == 0.0);
  require_jacobians_match_numeric(f, {sb}, {Block::Euclidean});
  CHECK_THROWS_AS(AccBiasPriorFactor(0.0), std::invalid_argument);
  CHECK_THROWS_AS(AccBiasPriorFactor(-1.0), std::invalid_argument);
}
