#include "stages/estimator/feature_weights.hpp"

#include <algorithm>

namespace dynavins::estimator {

namespace {
double momentumGain(int n, const FeatureWeightParams& p) {
  const double nn = std::min(n, p.max_momentum_count);
  return p.lambda_m * nn * nn;  // λm n_j², the curvature the momentum factor (eq. 9) adds
}
}  // namespace

double solveFeatureWeight(double r, double w_prev, int n, const FeatureWeightParams& p) {
  const double m = momentumGain(n, p);
  // d/dw of eq. (10) = 2 w r − 2 λw (1 − w) − 2 m (w̄ − w) = 0.
  const double w = (p.lambda_w + m * w_prev) / (r + p.lambda_w + m);
  return std::clamp(w, 0.0, 1.0);
}

double featureWeightCost(double w, double r, double w_prev, int n, const FeatureWeightParams& p) {
  const double m = momentumGain(n, p);
  return w * w * r + p.lambda_w * (1 - w) * (1 - w) + m * (w_prev - w) * (w_prev - w);
}

double meanSquaredResidual(const std::vector<double>& squared_norms) {
  if (squared_norms.empty()) return 0.0;
  double s = 0;
  for (double v : squared_norms) s += v;
  return s / static_cast<double>(squared_norms.size());
}

}  // namespace dynavins::estimator
