// The closed-form weight step against a brute-force minimisation of eq. (10).
#include <catch2/catch.hpp>

#include <random>

#include "stages/estimator/feature_weights.hpp"

using namespace dynavins::estimator;

namespace {
double bruteForceMinimiser(double r, double w_prev, int n, const FeatureWeightParams& p) {
  double best_w = 0, best = 1e300;
  for (int i = 0; i <= 200000; ++i) {
    const double w = i / 200000.0;
    const double c = featureWeightCost(w, r, w_prev, n, p);
    if (c < best) best = c, best_w = w;
  }
  return best_w;
}
}  // namespace

TEST_CASE("closed-form weight equals the brute-force minimiser of eq. 10", "[feature_weights]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> r_dist(0.0, 20.0), w_dist(0.0, 1.0), lam(0.0, 3.0);
  std::uniform_int_distribution<int> n_dist(0, 15);
  for (int k = 0; k < 200; ++k) {
    FeatureWeightParams p;
    p.lambda_w = 0.05 + lam(rng);
    p.lambda_m = (k % 4 == 0) ? 0.0 : lam(rng);
    const double r = (k % 10 == 0) ? 0.0 : r_dist(rng);
    const double w_prev = w_dist(rng);
    const int n = n_dist(rng);
    const double w = solveFeatureWeight(r, w_prev, n, p);
    CHECK(w >= 0.0);
    CHECK(w <= 1.0);
    CHECK(w == Approx(bruteForceMinimiser(r, w_prev, n, p)).margin(2e-5));
  }
}

TEST_CASE("without momentum the weight is eq. 7 and the converged loss eq. 8", "[feature_weights]") {
  FeatureWeightParams p;
  p.lambda_w = 1.0;
  p.lambda_m = 0.0;
  for (double r : {0.0, 0.1, 1.0, 4.0, 100.0}) {
    const double w = solveFeatureWeight(r, 0.3, 5, p);
    CHECK(w == Approx(p.lambda_w / (r + p.lambda_w)));
    CHECK(featureWeightCost(w, r, 0.3, 5, p) == Approx(p.lambda_w * r / (p.lambda_w + r)));
  }
  // r = 1 (RMS error of one noise sigma per observation) is where the weight crosses 0.5.
  CHECK(solveFeatureWeight(1.0, 1.0, 0, p) == Approx(0.5));
}

TEST_CASE("momentum holds a long-tracked weight against a burst of residual", "[feature_weights]") {
  FeatureWeightParams p;  // paper defaults λw = 1, λm = 0.2
  const double burst = 9.0;  // a 3-sigma RMS error, e.g. under aggressive motion
  const double fresh = solveFeatureWeight(burst, 1.0, 0, p);
  const double long_tracked = solveFeatureWeight(burst, 1.0, 8, p);
  CHECK(fresh < 0.15);
  CHECK(long_tracked > 0.6);
  // ...and keeps a long-rejected feature low even when it happens to fit (paper Fig. 3(c)).
  CHECK(solveFeatureWeight(0.0, 0.0, 8, p) < 0.1);
  // n_j saturates: beyond the cap the weight no longer changes.
  CHECK(solveFeatureWeight(burst, 1.0, 50, p) == Approx(solveFeatureWeight(burst, 1.0, p.max_momentum_count, p)));
}

TEST_CASE("mean squared residual is the per-observation mean", "[feature_weights]") {
  CHECK(meanSquaredResidual({}) == 0.0);
  CHECK(meanSquaredResidual({1.0, 2.0, 6.0}) == Approx(3.0));
}
