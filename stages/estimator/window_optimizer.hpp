#pragma once
// Builds and solves the window's nonlinear least squares (paper eq. 1 for huber, eq. 11 for dynavins)
// and keeps the marginalisation prior across slides.
//
// dynavins: alternating optimisation (paper III-C): weights first in closed form with the state fixed
// (IMU-propagated newest frame, last solve for the rest), then the state with the weights fixed, until
// the share of settled weights reaches `alternating_converge` or the iteration budget is spent. The
// alternations share one Ceres iteration budget (max_num_iterations, like the huber solve), which is why
// robust BA costs about what a Huber BA does.

#include <memory>
#include <vector>

#include "stages/estimator/ba_mode.hpp"
#include "stages/estimator/feature_weights.hpp"
#include "messages/window_estimate.hpp"
#include "stages/estimator/window_features.hpp"
#include "stages/estimator/window_state.hpp"

namespace dynavins::estimator {

class MarginalizationInfo;
class ImuPathFromRest;

struct WindowSolveOptions {
  BaLoss loss = BaLoss::Dynavins;
  bool stereo = true;
  int max_iterations = 8;          ///< Ceres iterations per window solve (all alternations together)
  double max_solver_time_s = 0.04;
  double gravity = 9.81;
  double sqrt_info = kNominalFocalPx / 1.5;  ///< reprojection noise σ = 1.5 px at 460 px (VINS-Fusion); key reprojection_sigma_px
  FeatureWeightParams weights;
  double alternating_converge = 0.9;  ///< share of weights that must have settled (|Δw| < settle_tol)
  double settle_tolerance = 0.05;
  int max_alternations = 4;
  double margin_feature_thresh = 0.1;  ///< features under this weight stay out of the prior (dynavins)
  bool weighted_huber = true;  ///< dynavins: Huber loss on each weighted observation too (not the paper's)
  double zero_velocity_sigma = 0.01;  ///< m/s, of the zero-velocity factor on slots found at rest
  /// m/s², ours (issue 23; 0 = off, as VINS-Fusion): zero-mean prior on the first window's accelerometer
  /// bias, carried on by the marginalisation (acc_bias_prior_factor.hpp; key acc_bias_prior_sigma).
  double acc_bias_prior_sigma = 0.0;
  /// Ours (dynavins, mono only; 0 = off): a feature whose best-fit depth is more than this many times
  /// the largest distance between its anchor camera and the others that saw it in the window (parallax
  /// under 1/K rad), while the median depth of the features in use is within that reach, stays out of the
  /// state step and the prior (ŵ_j = 0; key mono_max_depth_baselines; window_optimizer.cpp).
  double mono_max_depth_baselines = 30.0;
};

class WindowOptimizer {
 public:
  explicit WindowOptimizer(WindowSolveOptions options);
  ~WindowOptimizer();

  /// Solves slots 0..newest. Updates the states, feature depths and (dynavins) weights in place. With
  /// `rest_path` (dynavins), the weight step judges the slots that path reaches on it instead of on the
  /// solved states (imu_path_from_rest.hpp).
  SolveStats solve(WindowState& s, int newest, WindowFeatures& features,
                   const ImuPathFromRest* rest_path = nullptr);

  /// Marginalises slot 0 (the oldest keyframe) into the prior; call before the window slides.
  void marginalize_oldest(WindowState& s, int newest, WindowFeatures& features);
  /// Marginalises the second-newest slot's pose out of the prior (its measurements are dropped, as in
  /// VINS-Fusion); call before that slot is removed.
  void marginalize_second_newest(WindowState& s, int newest);

  void reset();
  bool has_prior() const { return prior_ != nullptr; }
  /// The marginalisation prior the next solve uses (null when there is none); read-only (tests).
  const MarginalizationInfo* prior() const { return prior_.get(); }
  const WindowSolveOptions& options() const { return opt_; }

  /// Mean whitened squared reprojection residual of a feature over its weighted observations (the r_j
  /// of feature_weights.hpp) at the current states.
  double feature_residual(const WindowState& s, const WindowFeature& f) const;

 private:
  /// Runs the Schur step; when no information is left, drops the prior (logged) and returns false.
  bool marginalize_or_drop(MarginalizationInfo& info);

  WindowSolveOptions opt_;
  std::shared_ptr<MarginalizationInfo> prior_;
  std::vector<double*> prior_blocks_;
};

}  // namespace dynavins::estimator
