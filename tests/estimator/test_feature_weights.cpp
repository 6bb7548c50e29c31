// The closed-form weight step against a brute-force minimisation of eq. (10).
#include <catch2/catch.hpp>

#include <random>

#include "stages/estimator/feature_weights.hpp"

using namespace dynavins::estimator;

namespace {
double brute_force_minimiser(double r, double w_prev, int n, const FeatureWeightParams& p) {
  double best_w = 0, best = 1e300;
  for (int i = 0; i <= 200000; ++i) {
    const double w = i / 200000.0;
    const double c = feature_weight_cost(w, r, w_prev, n, p);
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
    const double w = solve_feature_weight(r, w_prev, n, p);
    CHECK(w >= 0.0);
    CHECK(w <= 1.0);
    CHECK(w == Approx(brute_force_minimiser(r, w_prev, n, p)).margin(2e-5));
  }
}

TEST_CASE("without momentum the weight is eq. 7 and the converged loss eq. 8", "[feature_weights]") {
  FeatureWeightParams p;
  p.lambda_w = 1.0;
  p.lambda_m = 0.0;
  for (double r : {0.0, 0.1, 1.0, 4.0, 100.0}) {
    const double w = solve_feature_weight(r, 0.3, 5, p);
    CHECK(w == Approx(p.lambda_w / (r + p.lambda_w)));
    CHECK(feature_weight_cost(w, r, 0.3, 5, p) == Approx(p.lambda_w * r / (p.lambda_w + r)));
  }
  // r = 1 (RMS error of one noise sigma per observation) is where the weight crosses 0.5.
  CHECK(solve_feature_weight(1.0, 1.0, 0, p) == Approx(0.5));
}

TEST_CASE("momentum holds a long-tracked weight against a burst of residual", "[feature_weights]") {
  FeatureWeightParams p;  // paper defaults λw = 1, λm = 0.2
  const double burst = 9.0;  // a 3-sigma RMS error, e.g. under aggressive motion
  const double fresh = solve_feature_weight(burst, 1.0, 0, p);
  const double long_tracked = solve_feature_weight(burst, 1.0, 8, p);
  CHECK(fresh < 0.15);
  CHECK(long_tracked > 0.6);
  // ...and keeps a long-rejected feature low even when it happens to fit (paper Fig. 3(c)).
  CHECK(solve_feature_weight(0.0, 0.0, 8, p) < 0.1);
  // n_j saturates: beyond the cap the weight no longer changes.
  CHECK(solve_feature_weight(burst, 1.0, 50, p) == Approx(solve_feature_weight(burst, 1.0, p.max_momentum_count, p)));
}

TEST_CASE("mean squared residual is the per-observation mean", "[feature_weights]") {
  CHECK(mean_squared_residual({}) == 0.0);
  CHECK(mean_squared_residual({1.0, 2.0, 6.0}) == Approx(3.0));
}

TEST_CASE("state step: a kept feature at full weight, a rejected one relative to a one-sigma track",
          "[feature_weights]") {
  FeatureWeightParams p;  // λw = 1: a one-sigma track (r = 1) has weight 0.5
  p.lambda_m = 0.0;
  p.kept_full_weight = true;
  // Static tracks at ordinary noise (RMS error below one sigma) enter the state solve at full weight,
  // as under Huber, though their eq. (10) weights are 0.5-1.
  for (double r : {0.0, 0.3, 0.7, 1.0}) CHECK(state_step_weight(solve_feature_weight(r, 1.0, 0, p), p) == Approx(1.0));
  // Beyond one sigma the state weight falls with r, and the weighted cost ŵ² r of a far outlier vanishes.
  double previous = 1.0;
  for (double r : {1.5, 3.0, 10.0, 100.0, 1e4}) {
    const double w_hat = state_step_weight(solve_feature_weight(r, 1.0, 0, p), p);
    CHECK(w_hat < previous);
    CHECK(w_hat == Approx(2.0 / (1.0 + r)));  // w / 0.5
    previous = w_hat;
  }
  CHECK(state_step_weight(solve_feature_weight(1e4, 1.0, 0, p), p) * state_step_weight(solve_feature_weight(1e4, 1.0, 0, p), p) * 1e4 < 1e-3);
  // Other λw: the line is still the weight of a one-sigma track.
  p.lambda_w = 4.0;  // γ = 2
  CHECK(state_step_weight(solve_feature_weight(1.0, 1.0, 0, p), p) == Approx(1.0));
  CHECK(state_step_weight(solve_feature_weight(3.0, 1.0, 0, p), p) == Approx((4.0 / 7.0) / 0.8));
  // Switched off, the state step uses w_j itself (the paper's eq. 11).
  p.kept_full_weight = false;
  CHECK(state_step_weight(0.3, p) == 0.3);
}

TEST_CASE("r_j is per residual component: a track at exactly the configured noise has r_j ~ 1, weight ~ 0.5",
          "[feature_weights]") {
  FeatureWeightParams p;
  p.lambda_m = 0.0;
  p.residual_per_component = true;
  // Whitened 2-D residuals with unit variance per component (the noise model): E[|e|^2] = 2.
  std::mt19937 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> sq;
  for (int k = 0; k < 20000; ++k) {
    const double ex = unit(rng), ey = unit(rng);
    sq.push_back(ex * ex + ey * ey);
  }
  const double r = feature_residual_scale(sq, p);
  CHECK(r == Approx(1.0).margin(0.03));
  CHECK(solve_feature_weight(r, 1.0, 0, p) == Approx(0.5).margin(0.01));
  // Per observation, the same consistent track would have r ~ 2 and be rejected (weight ~ 1/3).
  p.residual_per_component = false;
  CHECK(feature_residual_scale(sq, p) == Approx(2.0).margin(0.06));
  CHECK(solve_feature_weight(feature_residual_scale(sq, p), 1.0, 0, p) < 0.4);
}

TEST_CASE("oracle_labels overrules the state step's weight by the simulator's label, only where it knows one") {
  FeatureWeightParams p;
  for (int label : {-1, 0, 3}) CHECK(oracle_state_weight(0.3, label, p) == 0.3);  // off: untouched
  p.oracle_labels = 1;  // static tracks at full weight
  CHECK(oracle_state_weight(0.3, 0, p) == 1.0);
  CHECK(oracle_state_weight(0.3, 2, p) == 0.3);
  p.oracle_labels = 2;  // moving tracks out
  CHECK(oracle_state_weight(0.3, 0, p) == 0.3);
  CHECK(oracle_state_weight(0.9, 2, p) == 0.0);
  p.oracle_labels = 3;  // both
  CHECK(oracle_state_weight(0.3, 0, p) == 1.0);
  CHECK(oracle_state_weight(0.9, 7, p) == 0.0);
  CHECK(oracle_state_weight(0.4, -1, p) == 0.4);  // real input has no labels: the weights decide
}
