#pragma once
// The weight step of DynaVINS' robust BA (paper III-C/D): with the state fixed, each feature's weight
// w_j minimises eq. (10)
//     w² r_j + λw (1 − w)² + λm (n_j (w̄_j − w))²,
// a quadratic in w, so w_j = (λw + λm n_j² w̄_j) / (r_j + λw + λm n_j²), clamped to [0, 1]; with λm = 0 it
// is eq. (7), w_j = λw / (r_j + λw).
//
// Scale of r_j (a deliberate choice, see DESIGN §1): the paper's r_j sums the squared reprojection
// residuals of the feature's observations. Summed, a static feature seen in ten frames at ordinary noise
// already falls below 0.5 with λw = 1, and the weight would depend on the track length. We use the MEAN
// over the feature's weighted observations (every observation except the same-frame stereo one) of the
// squared residual whitened by the reprojection noise (σ = 1.5 px, VINS-Fusion's): r_j = 1 means an RMS
// error of σ per observation, which is where w_j crosses 0.5 at λw = 1. Track length enters through the
// momentum term instead, as the paper intends.

#include <vector>

namespace dynavins::estimator {

/// Settings of the weight step (from EstimatorOptions: lambda_w, lambda_m, momentum_on).
struct FeatureWeightParams {
  double lambda_w = 1.0;  ///< λw of eq. (2)
  double lambda_m = 0.2;  ///< λm of eq. (10); 0 gives the regularisation-only ablation (eq. 7)
  int max_momentum_count = 10;  ///< n_j saturates here (one window of solves), so an early wrong weight
                                ///< can still be undone by a long run of consistent residuals
};

/// Closed-form minimiser of eq. (10) over w ∈ [0, 1] for mean whitened squared residual `r`, previous
/// weight `w_prev` and solve count `n` (momentum ignored when n == 0 or λm == 0).
double solveFeatureWeight(double r, double w_prev, int n, const FeatureWeightParams& p);

/// The value of eq. (10) at weight `w` (used by tests and for the converged loss).
double featureWeightCost(double w, double r, double w_prev, int n, const FeatureWeightParams& p);

/// Mean of squared whitened residual norms: the r_j above. Empty input gives 0.
double meanSquaredResidual(const std::vector<double>& squared_norms);

}  // namespace dynavins::estimator
