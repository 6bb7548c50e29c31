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
// squared residual whitened by the reprojection noise (σ = 1.5 px, VINS-Fusion's), and per residual
// COMPONENT (key residual_per_component, ours): the noise model gives each of the two components of a
// reprojection residual the variance σ², so a static feature tracked at exactly the configured noise has
// E[‖e‖²] = 2 (chi-square with 2 dof), and per observation (the earlier normalisation) its r_j ≈ 2 put it
// at w_j ≈ 1/3, rejected. Divided by the 2 components, r_j = 1 means an RMS error of σ per axis, the
// noise the config declares, which is where w_j crosses 0.5 at λw = 1. Off by default (per observation,
// r_j = 1 is an RMS error of σ in norm): measured on one draw each, it kept more static features on every
// scene but cost ATE on `none` (README, "Street scenes"). Track length enters through the momentum term
// instead, as the paper intends.
//
// Weight in the state step (a deliberate change to eq. 11, ours; key kept_full_weight): eq. 11 puts
// w_j² r_j on every feature, w_j² = (λw / (λw + r_j))², a Geman-McClure-like kernel with the nominal σ
// as its scale, which down-weights every track with r_j > 0 where Huber, the baseline, keeps full weight
// up to one σ. With the key the state step uses the weight RELATIVE to what a consistent feature gets:
// ŵ_j = min(1, w_j / w_c) with w_c = λw / (λw + 1), the eq. (7) weight of a track whose RMS error is one
// σ (r_j = 1; w_c = 0.5 at λw = 1, the line between kept and rejected). A kept feature enters the state
// step at full weight, as under Huber; a rejected one at w_j / w_c, which still falls as 1/r_j (its cost
// ŵ_j² r_j → (λw + 1)² / r_j, bounded and redescending). The weight step itself (eq. 10, momentum, the
// reported w_j) is unchanged. Off by default, measured over noise draws (README, "Street scenes"): it
// removes dynavins' cost on the fast static street and cuts the error behind a leading truck by a third
// (stereo), but costs 20-25 % on our drone scenes `none` and `high`, and in mono it is worse everywhere.
// Measured against the simulator's truth, the down-weighting is not uniform: a static track's median
// r_j is ~0.01 (w_j² ~ 0.98), and the kept static tracks the kernel does down-weight (w_j 0.5-0.9) are
// mostly tracks that drifted (median true error 1.7 px, a tenth above 7 px; `bench_estimator`), which
// the key gives full weight.

#include <vector>

namespace dynavins::estimator {

/// Settings of the weight step (from EstimatorOptions: lambda_w, lambda_m, momentum_on).
struct FeatureWeightParams {
  double lambda_w = 1.0;  ///< λw of eq. (2)
  double lambda_m = 0.2;  ///< λm of eq. (10); 0 gives the regularisation-only ablation (eq. 7)
  int max_momentum_count = 10;  ///< n_j saturates here (one window of solves), so an early wrong weight
                                ///< can still be undone by a long run of consistent residuals
  bool kept_full_weight = false;  ///< state step: ŵ_j = min(1, w_j / w_c) (above); false: ŵ_j = w_j (eq. 11)
  bool residual_per_component = false;  ///< r_j per residual component (above); false: per observation
  /// Diagnostic, simulated input only (key oracle_labels; 0 = off): the simulator's labels overrule the
  /// state step's weight, bit 1 = static tracks at full weight, bit 2 = moving ones at 0 (3 = both). It measures how
  /// much of an error the weights' verdicts cause (what a perfect verdict would give); never a setting.
  int oracle_labels = 0;
};

/// Closed-form minimiser of eq. (10) over w ∈ [0, 1] for mean whitened squared residual `r`, previous
/// weight `w_prev` and solve count `n` (momentum ignored when n == 0 or λm == 0).
double solve_feature_weight(double r, double w_prev, int n, const FeatureWeightParams& p);

/// The weight the state step applies to a feature of eq. (10) weight `w` (ŵ_j above).
double state_step_weight(double w, const FeatureWeightParams& p);

/// The state step's weight of a feature of weight `state_weight` with the simulator's label `sim_label`
/// (0 static, > 0 a moving object, < 0 unknown) under p.oracle_labels; unknown labels are left alone.
double oracle_state_weight(double state_weight, int sim_label, const FeatureWeightParams& p);

/// The value of eq. (10) at weight `w` (used by tests and for the converged loss).
double feature_weight_cost(double w, double r, double w_prev, int n, const FeatureWeightParams& p);

/// Mean of squared whitened residual norms (per observation). Empty input gives 0.
double mean_squared_residual(const std::vector<double>& squared_norms);

/// The r_j above from the squared whitened norms of a feature's 2-D reprojection residuals: their mean,
/// per residual component when p.residual_per_component.
double feature_residual_scale(const std::vector<double>& squared_norms, const FeatureWeightParams& p);

}  // namespace dynavins::estimator
