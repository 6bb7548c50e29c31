#include "stages/estimator/feature_weights.hpp"

#include <algorithm>

namespace dynavins::estimator {

namespace {
double momentum_gain(int n, const FeatureWeightParams& p) {
  const double nn = std::min(n, p.max_momentum_count);
  return p.lambda_m * nn * nn;  // λm n_j², the curvature the momentum factor (eq. 9) adds
}
}  // namespace

double solve_feature_weight(double r, double w_prev, int n, const FeatureWeightParams& p) {
  const double m = momentum_gain(n, p);
  // d/dw of eq. (10) = 2 w r − 2 λw (1 − w) − 2 m (w̄ − w) = 0.
  const double w = (p.lambda_w + m * w_prev) / (r + p.lambda_w + m);
  return std::clamp(w, 0.0, 1.0);
}

double state_step_weight(double w, const FeatureWeightParams& p) {
  if (!p.kept_full_weight) return w;
  const double w_consistent = p.lambda_w / (p.lambda_w + 1.0);  // eq. (7) at r_j = 1 (RMS error one σ)
  if (!(w_consistent > 0)) return w;                            // λw = 0: every weight is 0 anyway
  return std::min(1.0, w / w_consistent);
}

double oracle_state_weight(double state_weight, int sim_label, const FeatureWeightParams& p) {
  if (sim_label == 0 && (p.oracle_labels & 1)) return 1.0;  // bit 1: static tracks at full weight
  if (sim_label > 0 && (p.oracle_labels & 2)) return 0.0;   // bit 2: moving tracks out
  return state_weight;
}

double feature_weight_cost(double w, double r, double w_prev, int n, const FeatureWeightParams& p) {
  const double m = momentum_gain(n, p);
  return w * w * r + p.lambda_w * (1 - w) * (1 - w) + m * (w_prev - w) * (w_prev - w);
}

double mean_squared_residual(const std::vector<double>& squared_norms) {
  if (squared_norms.empty()) return 0.0;
  double s = 0;
  for (double v : squared_norms) s += v;
  return s / static_cast<double>(squared_norms.size());
}

double feature_residual_scale(const std::vector<double>& squared_norms, const FeatureWeightParams& p) {
  constexpr double kComponentsPerObservation = 2.0;  // a reprojection residual is 2-D
  const double per_observation = mean_squared_residual(squared_norms);
  return p.residual_per_component ? per_observation / kComponentsPerObservation : per_observation;
}

}  // namespace dynavins::estimator
