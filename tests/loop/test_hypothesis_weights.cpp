// Closed-form weight step of paper IV-C eq. 16-17 (solve_hypothesis_weights) against a brute-force grid
// search of E(w0, w1) over [0, 1]^2, and its limiting behaviour.
#include <catch2/catch.hpp>

#include <limits>

#include "stages/loop/graph/hypothesis_weights.hpp"

using namespace dynavins::loop;

namespace {
HypothesisWeights brute_force(double R0, int n0, double R1, int n1, double lambda, int steps = 1000) {
  HypothesisWeights best;
  double best_e = std::numeric_limits<double>::infinity();
  for (int a = 0; a <= steps; ++a)
    for (int b = 0; b <= (n1 > 0 ? steps : 0); ++b) {
      const double w0 = a / static_cast<double>(steps), w1 = b / static_cast<double>(steps);
      const double e = hypothesis_weight_energy(w0, w1, R0, n0, R1, n1, lambda);
      if (e < best_e) best_e = e, best = HypothesisWeights{w0, w1};
    }
  return best;
}
}  // namespace

TEST_CASE("solve_hypothesis_weights matches a brute-force minimisation of eq. 16-17", "[loop][weights]") {
  struct Case {
    double res0;  // R_0
    int n0;
    double res1;  // R_1
    int n1;
    double lambda;
  };
  const Case cases[] = {{0.1, 3, 400.0, 5, 1.0}, {400.0, 5, 0.1, 3, 1.0}, {2.0, 4, 3.0, 4, 1.0},
                        {0.0, 3, 50.0, 2, 1.0},  {10.0, 1, 10.0, 1, 0.5}, {5.0, 6, 0.0, 0, 1.0},
                        {90.0, 3, 0.0, 0, 1.0},  {1.0, 2, 1.0, 7, 3.0}};
  for (const Case& c : cases) {
    const HypothesisWeights w = solve_hypothesis_weights(c.res0, c.n0, c.res1, c.n1, c.lambda);
    const HypothesisWeights b = brute_force(c.res0, c.n0, c.res1, c.n1, c.lambda);
    INFO("R0 " << c.res0 << " n0 " << c.n0 << " R1 " << c.res1 << " n1 " << c.n1 << " lambda " << c.lambda);
    CHECK(w.w0 == Approx(b.w0).margin(2e-3));
    CHECK(w.w1 == Approx(b.w1).margin(2e-3));
    const double e = hypothesis_weight_energy(w.w0, w.w1, c.res0, c.n0, c.res1, c.n1, c.lambda);
    CHECK(e <= hypothesis_weight_energy(b.w0, b.w1, c.res0, c.n0, c.res1, c.n1, c.lambda) + 1e-12);
    CHECK(w.w0 >= 0.0);
    CHECK(w.w1 >= 0.0);
    CHECK(w.w0 + w.w1 <= 1.0 + 1e-12);
  }
}

TEST_CASE("solve_hypothesis_weights: limits", "[loop][weights]") {
  // A consistent hypothesis against a far-off one: nearly all weight on the consistent one.
  const HypothesisWeights a = solve_hypothesis_weights(0.05, 3, 2000.0, 5, 1.0);
  CHECK(a.w0 > 0.99);
  CHECK(a.w1 < 0.01);
  // Both consistent (zero residual): split evenly, sum 1.
  const HypothesisWeights b = solve_hypothesis_weights(0.0, 3, 0.0, 4, 1.0);
  CHECK(b.w0 == Approx(0.5));
  CHECK(b.w1 == Approx(0.5));
  // A single false hypothesis: weight -> 0 (all-false group, IV-C last paragraph); a single true one -> 1.
  CHECK(solve_hypothesis_weights(4000.0, 4, 0.0, 0, 1.0).w0 < 0.01);
  CHECK(solve_hypothesis_weights(0.0, 4, 0.0, 0, 1.0).w0 == Approx(1.0));
  // Eq. 16 divides by |H|^2: the same per-loop residual weighs less in a larger hypothesis.
  CHECK(solve_hypothesis_weights(3 * 10.0, 3, 0.0, 0, 1.0).w0 < solve_hypothesis_weights(6 * 10.0, 6, 0.0, 0, 1.0).w0);
}
