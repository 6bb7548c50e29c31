// Closed-form weight step of paper IV-C eq. 16-17 (see hypothesis_weights.hpp).
//
// Derivation. Write a_h = R_h / |H_h|^2 >= 0 and lambda = lambda_l > 0. E is a convex quadratic:
//     E = a0 w0^2 + a1 w1^2 + lambda (1 - w0 - w1)^2.
// Setting the gradient to zero:
//     dE/dw0 = 2 a0 w0 - 2 lambda (1 - w0 - w1) = 0
//     dE/dw1 = 2 a1 w1 - 2 lambda (1 - w0 - w1) = 0
// i.e. the 2x2 linear system
//     [a0 + lambda   lambda    ] [w0]   [lambda]
//     [lambda        a1 + lambda] [w1] = [lambda],
// with determinant D = (a0 + lambda)(a1 + lambda) - lambda^2 = a0 a1 + lambda (a0 + a1), so
//     w0 = lambda a1 / D,   w1 = lambda a0 / D.
// For a0, a1 >= 0 (not both 0) these are in [0, 1] and w0 + w1 = lambda (a0 + a1) / D <= 1, so the box
// constraint of eq. 17 is inactive; the result is clamped anyway against rounding. The hypothesis with the
// smaller a_h gets the larger weight; a false hypothesis (large a_h) tends to lambda a_true / (a_f a_true
// + ...) -> 0. Degenerate cases:
//   - a0 = a1 = 0: E = lambda (1 - w0 - w1)^2, every point of w0 + w1 = 1 is a minimiser; we take
//     w0 = w1 = 1/2 (symmetric, deterministic).
//   - one hypothesis (|H1| = 0, w1 fixed at 0): dE/dw0 = 2 a0 w0 - 2 lambda (1 - w0) = 0 gives
//     w0 = lambda / (a0 + lambda).
#include "stages/loop/graph/hypothesis_weights.hpp"

#include <algorithm>

namespace dynavins::loop {

namespace {
double clamp01(double w) { return std::min(1.0, std::max(0.0, w)); }
}  // namespace

HypothesisWeights solve_hypothesis_weights(double R0, int size0, double R1, int size1, double lambda_l) {
  const double a0 = std::max(0.0, R0) / (static_cast<double>(size0) * size0);
  if (size1 <= 0) return HypothesisWeights{clamp01(lambda_l / (a0 + lambda_l)), 0.0};
  const double a1 = std::max(0.0, R1) / (static_cast<double>(size1) * size1);
  const double D = a0 * a1 + lambda_l * (a0 + a1);
  if (D <= 0.0) return HypothesisWeights{0.5, 0.5};
  return HypothesisWeights{clamp01(lambda_l * a1 / D), clamp01(lambda_l * a0 / D)};
}

double hypothesis_weight_energy(double w0, double w1, double R0, int size0, double R1, int size1, double lambda_l) {
  const double a0 = R0 / (static_cast<double>(size0) * size0);
  const double a1 = size1 > 0 ? R1 / (static_cast<double>(size1) * size1) : 0.0;
  const double phi = 1.0 - w0 - w1;  // eq. 17
  return a0 * w0 * w0 + a1 * w1 * w1 + lambda_l * phi * phi;
}

}  // namespace dynavins::loop
