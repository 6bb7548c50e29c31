#pragma once
// The weight step of the selective optimisation (paper IV-C, eq. 16-17) in closed form: with the poses
// fixed, the weights w^0, w^1 of one group minimise
//     E(w0, w1) = w0^2 / |H0|^2 * R0 + w1^2 / |H1|^2 * R1 + lambda_l (1 - w0 - w1)^2,   w0, w1 in [0, 1],
// where R_h = sum over the loops of H^h of ||r||^2_{P_L} (the whitened squared loop residuals). Eq. 16
// scales each residual by w/|H| inside the norm, so the weight enters squared and the cardinality too.

namespace dynavins::loop {

struct HypothesisWeights {
  double w0 = 0.0;
  double w1 = 0.0;
};

/// Minimiser of E above. size1 == 0 means the group has one hypothesis only (w1 = 0). size0 must be > 0.
HypothesisWeights solve_hypothesis_weights(double R0, int size0, double R1, int size1, double lambda_l);

/// E(w0, w1) itself (for tests and diagnostics).
double hypothesis_weight_energy(double w0, double w1, double R0, int size0, double R1, int size1, double lambda_l);

}  // namespace dynavins::loop
