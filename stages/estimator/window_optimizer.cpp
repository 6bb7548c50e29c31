#include "stages/estimator/window_optimizer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>

#include "stages/estimator/factors/acc_bias_prior_factor.hpp"
#include "stages/estimator/factors/imu_factor.hpp"
#include "stages/estimator/factors/reprojection_factors.hpp"
#include "stages/estimator/factors/zero_velocity_factor.hpp"
#include "stages/estimator/imu_path_from_rest.hpp"
#include "stages/estimator/marginalization/marginalization_factor.hpp"
#include "stages/estimator/marginalization/marginalization_info.hpp"
#include "stages/estimator/pose_manifold.hpp"
#include "stages/estimator/window_gauge.hpp"

namespace dynavins::estimator {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// One visual residual of a feature: its cost, blocks, and whether DynaVINS weights it.
struct VisualResidual {
  std::shared_ptr<ceres::CostFunction> cost;
  std::vector<double*> blocks;
  bool weighted = false;
  int anchor_block = 0;  ///< index in `blocks` of the anchor pose (-1 for the stereo residual)
};

/// Every reprojection residual of `f` (paper III-D: the same-frame stereo residual is never weighted).
std::vector<VisualResidual> visual_residuals(WindowState& s, WindowFeature& f, const WindowSolveOptions& o) {
  std::vector<VisualResidual> out;
  const bool dyn = o.loss == BaLoss::Dynavins;
  const double* w = dyn ? &f.state_weight : nullptr;  // ŵ_j (feature_weights.hpp)
  const int i = f.start_slot;
  const Eigen::Vector2d& xy_i = f.obs[0].xy;
  double* pose_i = s.pose[i].data();
  double* ex0 = s.extrinsic[0].data();
  double* ex1 = s.extrinsic[1].data();
  for (size_t k = 0; k < f.obs.size(); ++k) {
    const int j = i + static_cast<int>(k);
    const FeatureObservation& o_j = f.obs[k];
    if (j != i) {
      out.push_back({std::make_shared<ProjectionTwoFrameOneCamFactor>(xy_i, o_j.xy, o.sqrt_info, w),
                     {pose_i, s.pose[j].data(), ex0, &f.inv_depth}, dyn, 0});
    }
    if (!o.stereo || !o_j.has_right) continue;
    if (j != i) {
      out.push_back({std::make_shared<ProjectionTwoFrameTwoCamFactor>(xy_i, o_j.xy_right, o.sqrt_info, w),
                     {pose_i, s.pose[j].data(), ex0, ex1, &f.inv_depth}, dyn, 0});
    } else {
      out.push_back({std::make_shared<ProjectionOneFrameTwoCamFactor>(xy_i, o_j.xy_right, o.sqrt_info),
                     {ex0, ex1, &f.inv_depth}, false, -1});
    }
  }
  return out;
}

/// VINS-Fusion's loss: Huber with delta 1 (one noise sigma) on every visual residual in huber mode. In
/// dynavins mode the paper's weights replace it (eq. 4) unless `weighted_huber` keeps it under them: a
/// weight judges a whole track, the Huber loss bounds a single bad observation of a track still kept
/// (sim, stereo: e_shape ATE 0.31 -> 0.08 m, temporal_static 1.19 -> 0.85 m, the rest within 0.04 m; README).
std::shared_ptr<ceres::LossFunction> loss_for(const VisualResidual& r, const WindowSolveOptions& o) {
  // One stateless loss shared by every residual (Ceres does not own it here), not one per residual.
  static const auto kHuber = std::make_shared<ceres::HuberLoss>(1.0);
  if (o.loss == BaLoss::Dynavins && r.weighted && !o.weighted_huber) return nullptr;
  return kHuber;
}

bool imu_usable(const WindowState& s, int k) { return s.preint[k] && s.preint[k]->sum_dt() < 10.0; }

}  // namespace

bool WindowOptimizer::marginalize_or_drop(MarginalizationInfo& info) {
  try {
    info.marginalize();
    return true;
  } catch (const std::runtime_error& e) {
    // Nothing informative left to keep (e.g. every factor rejected): the window goes on without a prior.
    spdlog::warn("marginalisation dropped the prior: {}", e.what());
    reset();
    return false;
  }
}

WindowOptimizer::WindowOptimizer(WindowSolveOptions options) : opt_(options) {}
WindowOptimizer::~WindowOptimizer() = default;

void WindowOptimizer::reset() {
  prior_.reset();
  prior_blocks_.clear();
}

namespace {

/// The observations of one feature that the weight step looks at, projected from the anchor bearing at
/// inverse depth `rho` with the poses fixed.
struct FeatureGeometry {
  struct Obs {
    CameraPose cam;
    Eigen::Vector2d xy;
    bool weighted;  ///< false for the anchor's own stereo observation (paper III-D)
  };
  CameraPose anchor;
  Eigen::Vector3d bearing;  ///< anchor cam0, z = 1
  std::vector<Obs> obs;
  double sqrt_info = 1;
  double inverse_depth = 0;  ///< the best fit of the last feature_residual_with()

  Eigen::Vector2d residual(const Obs& o, double rho) const {
    const Eigen::Vector3d p_w = anchor.R * (bearing / rho) + anchor.p;
    const Eigen::Vector3d p_c = o.cam.R.transpose() * (p_w - o.cam.p);
    if (p_c.z() <= 1e-3) return Eigen::Vector2d(1e2, 1e2);  // behind the camera: as bad as it gets
    return sqrt_info * (p_c.head<2>() / p_c.z() - o.xy);
  }
  /// r_j of feature_weights.hpp over the weighted observations (feature_residual_scale).
  double weighted_mean(double rho, const FeatureWeightParams& p) const {
    std::vector<double> sq;
    for (const Obs& o : obs)
      if (o.weighted) sq.push_back(residual(o, rho).squaredNorm());
    return feature_residual_scale(sq, p);
  }
  /// Inverse depth that best explains every observation with the poses fixed (1-D Gauss-Newton).
  double best_inverse_depth(double rho) const {
    for (int it = 0; it < 5; ++it) {
      const double h = 1e-6 * std::max(rho, 1e-3);
      double H = 0, b = 0;
      for (const Obs& o : obs) {
        const Eigen::Vector2d e = residual(o, rho);
        const Eigen::Vector2d J = (residual(o, rho + h) - e) / h;
        H += J.squaredNorm();
        b += J.dot(e);
      }
      if (!(H > 0)) break;
      const double step = -b / H;
      rho = std::clamp(rho + step, 1e-3, 10.0);  // depth between 0.1 m and 1 km
      if (std::abs(step) < 1e-6) break;
    }
    return rho;
  }
  /// Largest distance from the anchor camera to a camera of the observations [m].
  double baseline() const {
    double b = 0;
    for (const Obs& o : obs) b = std::max(b, (o.cam.p - anchor.p).norm());
    return b;
  }
};

/// feature_residual() with the camera poses from `camera(slot, cam)` and `g` as reusable scratch.
template <typename CameraOf>
double feature_residual_with(const WindowFeature& f, const WindowSolveOptions& opt, const CameraOf& camera,
                           FeatureGeometry& g) {
  // r_j is measured at the depth that best explains all the feature's observations with the poses
  // fixed, not at the BA's current depth: once a feature's weight is low, the unweighted stereo
  // residual alone sets its BA depth, and a distant point with a slightly wrong disparity would then
  // keep a large temporal residual and never win its weight back. With the depth profiled out, r_j asks
  // only "is this track consistent with a static point under the estimated motion?". The stereo
  // observations of every frame stay in that fit, so an object moving with the camera (which a point at
  // infinity would explain without them) still does not fit.
  g.anchor = camera(f.start_slot, 0);
  g.bearing = Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0);
  g.sqrt_info = opt.sqrt_info;
  g.obs.clear();
  for (size_t k = 0; k < f.obs.size(); ++k) {
    const int j = f.start_slot + static_cast<int>(k);
    if (k > 0) g.obs.push_back({camera(j, 0), f.obs[k].xy, true});
    if (opt.stereo && f.obs[k].has_right) g.obs.push_back({camera(j, 1), f.obs[k].xy_right, k > 0});
  }
  g.inverse_depth = g.best_inverse_depth(f.inv_depth);
  return g.weighted_mean(g.inverse_depth, opt.weights);
}

/// Mono: did the track show no parallax where the window's typical point would have? With `g` filled by
/// feature_residual_with() and K = `max_depth_baselines`: its best-fit depth is beyond K times the
/// baseline b it was seen over (parallax under 1/K rad) while `median_depth`, that of the tracks in use,
/// is within K b. Such a track carries no depth the window can observe, and a point moving with the
/// camera (a truck leading it) looks exactly like one at infinity: its bearing keeps still while the
/// camera drives. Used at eq. 10's weight ~1, the truck's tracks (half the image) pulled the attitude and
/// with it the gravity the accelerometer subtracts, and the scale crept (README, "Street scenes"); the
/// state step now leaves them out (ŵ = 0, and out of the prior). A far static point loses only rotation,
/// which the gyroscope gives over a window. The median condition leaves the features alone where the
/// whole window lacks parallax (at rest, or creeping): there a still track is no evidence of anything.
bool depth_unobservable(const FeatureGeometry& g, double max_depth_baselines, double median_depth) {
  const double reach = max_depth_baselines * g.baseline();  // K b [m]; K = 0 reaches nothing: never true
  return median_depth < reach && g.inverse_depth * reach < 1.0;
}

/// Median depth of the features the last state step used (ŵ >= 0.5; from their inverse depth in the anchor
/// frame), so that the tracks it left out, which the truck's are, do not set it; 0 when there are none.
double median_kept_depth(const std::vector<WindowFeature*>& features) {
  std::vector<double> d;
  d.reserve(features.size());
  for (const WindowFeature* f : features)
    if (f->inv_depth > 0 && f->state_weight >= 0.5) d.push_back(1.0 / f->inv_depth);
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

/// Mono: does the track's recent life contradict a static point? `window_fit` is its fit over the window
/// (feature_residual_with), `past` its observations in the keyframes that left the window, `now_from_past` maps
/// their poses into the window's world of the moment. A point riding with the camera a few metres ahead (the
/// car ahead in its lane, at its speed) fits a static point within one window: against the forward motion its
/// bearing keeps still as a far point's would, while the camera's lane weaving gives it the parallax of a
/// nearer one, so depth_unobservable does not catch it, eq. 10 keeps it, and in the state step it drags the
/// attitude and the scale (on `street_jam`, mono, the two vehicles ahead were three fifths of its excess over its twin;
/// README, "Street scenes"). Over the keyframes before the window the camera drove several times as far, and
/// no one static point explains them all: the track's r_j over the window and its past together (the depth
/// refitted, the poses as estimated) is beyond eq. 7's line r_j = λw (w_j = 0.5). A static track's past fits
/// as well as its window does, up to the drift of the poses over those keyframes.
bool history_inconsistent(const FeatureGeometry& window_fit, const std::vector<PastObservation>& past,
                          const Eigen::Isometry3d& now_from_past, const FeatureWeightParams& p, FeatureGeometry& g) {
  g = window_fit;
  for (const PastObservation& o : past) {
    CameraPose c;
    c.R = now_from_past.linear() * o.cam.R;
    c.p = now_from_past * o.cam.p;
    g.obs.push_back({c, o.xy, true});
  }
  g.inverse_depth = g.best_inverse_depth(window_fit.inverse_depth);
  return g.weighted_mean(g.inverse_depth, p) > p.lambda_w;
}

}  // namespace

double WindowOptimizer::feature_residual(const WindowState& s, const WindowFeature& f) const {
  FeatureGeometry g;
  return feature_residual_with(f, opt_, [&s](int k, int c) { return s.camera(k, c); }, g);
}

namespace {

/// The window's nonlinear least squares as one Ceres problem (paper eq. 1 for huber; for dynavins eq. 11
/// with the weights w_j held fixed, which the reprojection factors read through pointers): the states of
/// slots 0..newest, the fixed extrinsics, then the residuals in this order: the marginalisation prior,
/// the IMU factors, the zero-velocity factors, every visual residual of the features in the BA.
class WindowProblem {
 public:
  WindowProblem(WindowState& s, int newest, WindowFeatures& features, const WindowSolveOptions& opt,
                const std::shared_ptr<MarginalizationInfo>& prior, const std::vector<double*>& prior_blocks)
      : problem_(problem_options()) {
    add_states(s, newest, opt);
    if (prior) add_cost(std::make_shared<MarginalizationFactor>(prior), nullptr, prior_blocks);
    add_imu(s, newest, opt);
    // Until the first marginalisation the bias prior sits on the oldest slot; from then on the prior carries it.
    if (!prior && opt.acc_bias_prior_sigma > 0)
      add_cost(std::make_shared<AccBiasPriorFactor>(opt.acc_bias_prior_sigma), nullptr, {s.speed_bias[0].data()});
    add_zero_velocity(s, newest, opt);
    add_visual(s, newest, features, opt);
  }
  WindowProblem(const WindowProblem&) = delete;
  WindowProblem& operator=(const WindowProblem&) = delete;

  ceres::Problem& problem() { return problem_; }
  /// The features whose residuals are in the problem (the ones the weight step of eq. 10 solves for).
  const std::vector<WindowFeature*>& features() const { return in_ba_; }

 private:
  static ceres::Problem::Options problem_options() {
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    // The blocks and residuals below are well-formed by construction; skip Ceres' per-call validation
    // (it only checks arguments, the problem and its solution are the same).
    po.disable_all_safety_checks = true;
    return po;
  }

  void add_cost(std::shared_ptr<ceres::CostFunction> cost, ceres::LossFunction* loss,
               const std::vector<double*>& blocks) {
    problem_.AddResidualBlock(cost.get(), loss, blocks);
    costs_.push_back(std::move(cost));
  }

  /// Pose and speed-bias of every slot; the camera extrinsics, fixed from config.
  void add_states(WindowState& s, int newest, const WindowSolveOptions& opt) {
    for (int k = 0; k <= newest; ++k) {
      problem_.AddParameterBlock(s.pose[k].data(), kPoseSize, &pose_manifold_);
      problem_.AddParameterBlock(s.speed_bias[k].data(), kSpeedBiasSize);
    }
    for (int c = 0; c < (opt.stereo ? 2 : 1); ++c) {
      problem_.AddParameterBlock(s.extrinsic[c].data(), kPoseSize, &pose_manifold_);
      problem_.SetParameterBlockConstant(s.extrinsic[c].data());
    }
  }

  /// Preintegrated IMU between consecutive slots (the inertial term of eq. 1).
  void add_imu(WindowState& s, int newest, const WindowSolveOptions& opt) {
    for (int k = 1; k <= newest; ++k) {
      if (!imu_usable(s, k)) continue;
      add_cost(std::make_shared<ImuFactor>(s.preint[k].get(), opt.gravity), nullptr,
              {s.pose[k - 1].data(), s.speed_bias[k - 1].data(), s.pose[k].data(), s.speed_bias[k].data()});
    }
  }

  /// Zero velocity on the slots found at rest (standstill_detector.hpp; not in the paper).
  void add_zero_velocity(WindowState& s, int newest, const WindowSolveOptions& opt) {
    for (int k = 0; k <= newest; ++k) {
      if (!s.still[k]) continue;
      add_cost(std::make_shared<ZeroVelocityFactor>(opt.zero_velocity_sigma), nullptr, {s.speed_bias[k].data()});
    }
  }

  /// Reprojection residuals (the visual term of eq. 1; weighted by w_j in eq. 11, see loss_for for the loss).
  void add_visual(WindowState& s, int newest, WindowFeatures& features, const WindowSolveOptions& opt) {
    for (auto& [id, f] : features.all()) {
      if (!f.in_ba() || f.start_slot > newest) continue;
      in_ba_.push_back(&f);
      for (VisualResidual& r : visual_residuals(s, f, opt)) add_cost(r.cost, loss_for(r, opt).get(), r.blocks);
    }
  }

  // Declared before the problem, which points into them: they outlive it.
  PoseManifold pose_manifold_;
  std::vector<std::shared_ptr<ceres::CostFunction>> costs_;
  ceres::Problem problem_;
  std::vector<WindowFeature*> in_ba_;
};

/// The Ceres state solves of one window solve and their shared budget: `max_iterations` over all of them
/// together (so a robust BA costs about what a Huber BA does) and `max_solver_time_s` (may be infinite).
class StateSolver {
 public:
  StateSolver(ceres::Problem& problem, const WindowSolveOptions& opt, SolveStats& st)
      : problem_(problem), st_(st), budget_(opt.max_iterations), time_left_(opt.max_solver_time_s) {
    so_.linear_solver_type = ceres::DENSE_SCHUR;
    so_.trust_region_strategy_type = ceres::DOGLEG;
    so_.num_threads = 1;  // stage libraries start no threads (pipeline/ does)
    so_.logging_type = ceres::SILENT;
  }

  /// Solves the states with everything else fixed for up to `iterations` (at least 1) and whatever time
  /// is left; returns whether Ceres converged.
  bool run(int iterations) {
    so_.max_num_iterations = std::max(1, iterations);
    so_.max_solver_time_in_seconds = std::max(1e-3, time_left_);
    ceres::Solver::Summary summary;
    ceres::Solve(so_, &problem_, &summary);
    // Iterations taken: summary.iterations[0] is the start point, not an iteration. The budget is
    // charged one more per call, for that start (an evaluation of every residual and Jacobian, as an
    // iteration costs; Ceres counts it in num_successful_steps, which is how this was charged before it
    // was noticed). So with a budget of 8 the alternation makes at most 2 state solves of 4 + 2
    // iterations where huber's one call makes 8 (issue 23, README "Street scenes").
    const int taken = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
    st_.ceres_iterations += taken;
    budget_ -= taken + 1;
    time_left_ -= summary.total_time_in_seconds;
    ++st_.alternations;
    return summary.termination_type == ceres::CONVERGENCE;
  }
  int iterations_left() const { return budget_; }
  bool exhausted() const { return budget_ <= 0 || !(time_left_ > 0); }

 private:
  ceres::Problem& problem_;
  SolveStats& st_;
  ceres::Solver::Options so_;
  int budget_;
  double time_left_;
};

/// The weight step (paper eq. 10 in closed form, solve_feature_weight) with the states fixed.
class WeightStep {
 public:
  /// `past_frame`: WindowFeatures::past_frame() when the features keep past observations, else null.
  WeightStep(const WindowState& s, int newest, const WindowSolveOptions& opt, const ImuPathFromRest* rest_path,
             const CameraPose* past_frame, SolveStats& st)
      : s_(s), newest_(newest), opt_(opt), rest_path_(rest_path), past_frame_(past_frame), st_(st),
        cameras_(newest + 1) {}

  /// Updates every feature's w_j from its residual r_j at the current states; returns the share of
  /// weights that moved less than settle_tolerance.
  double operator()(const std::vector<WindowFeature*>& features) {
    const auto t0 = Clock::now();
    // The states are fixed during the weight step: each slot's camera poses once, not per observation.
    for (int k = 0; k <= newest_; ++k) {
      const ImuPathFromRest::Pose* on_path = rest_path_ ? rest_path_->after_anchor(s_.t_ns[k]) : nullptr;
      if (on_path) {
        cameras_[k] = {s_.camera_at(on_path->p, on_path->q, 0), s_.camera_at(on_path->p, on_path->q, 1)};
      } else {
        cameras_[k] = {s_.camera(k, 0), s_.camera(k, 1)};
      }
    }
    auto camera = [this](int k, int c) -> const CameraPose& { return cameras_[k][c]; };
    int settled = 0;
    const bool judge_depth = !opt_.stereo && opt_.mono_max_depth_baselines > 0;  // depth_unobservable
    const double depth_median = judge_depth ? median_kept_depth(features) : 0.0;
    const bool judge_history = !opt_.stereo && past_frame_;  // history_inconsistent
    Eigen::Isometry3d now_from_past = Eigen::Isometry3d::Identity();
    if (judge_history) {
      // Slot 0 now against slot 0 when the past was recorded: the window floats within a solve.
      const CameraPose now = s_.camera(0, 0);
      now_from_past.linear() = now.R * past_frame_->R.transpose();
      now_from_past.translation() = now.p - now_from_past.linear() * past_frame_->p;
    }
    for (WindowFeature* f : features) {
      const double r = feature_residual_with(*f, opt_, camera, geometry_);
      const double w = solve_feature_weight(r, f->weight_prev, f->times_solved, opt_.weights);
      if (std::abs(w - f->weight) < opt_.settle_tolerance) ++settled;
      f->weight = w;
      // eq. 10 keeps such a track (it fits a point at infinity); it only stays out of the state step.
      const bool unobservable =
          (judge_depth && depth_unobservable(geometry_, opt_.mono_max_depth_baselines, depth_median)) ||
          (judge_history && !f->past.empty() &&
           history_inconsistent(geometry_, f->past, now_from_past, opt_.weights, history_geometry_));
      f->state_weight = unobservable ? 0.0 : state_step_weight(w, opt_.weights);
      f->state_weight = oracle_state_weight(f->state_weight, f->sim_label, opt_.weights);  // 0 = off: unchanged
    }
    st_.weight_ms += ms_since(t0);
    return features.empty() ? 1.0 : static_cast<double>(settled) / features.size();
  }

 private:
  const WindowState& s_;
  int newest_;
  const WindowSolveOptions& opt_;
  const ImuPathFromRest* rest_path_;
  const CameraPose* past_frame_;
  SolveStats& st_;
  std::vector<std::array<CameraPose, 2>> cameras_;
  FeatureGeometry geometry_, history_geometry_;
};

/// Alternating optimisation of eq. (11) (paper III-C): the weights w_j by eq. (10) with the states fixed,
/// then the states with the weights fixed, until the share of settled weights reaches
/// `alternating_converge` with Ceres converged, `max_alternations` is reached or the budget is spent.
/// Afterwards w̄_j = w_j and n_j grows by one (the momentum of eq. 9 for the next solve).
void alternate(const WindowState& s, int newest, const std::vector<WindowFeature*>& features,
               const WindowSolveOptions& opt, const ImuPathFromRest* rest_path, const CameraPose* past_frame,
               StateSolver& solver, SolveStats& st) {
  WeightStep weight_step(s, newest, opt, rest_path, past_frame, st);
  // Start from the previous weights (momentum's w̄) so "settled" compares against where we were.
  for (WindowFeature* f : features) f->weight = f->weight_prev;
  weight_step(features);
  for (int a = 0; a < opt.max_alternations && !solver.exhausted(); ++a) {
    const bool last = a + 1 == opt.max_alternations;
    const int budget = solver.iterations_left();
    const bool converged = solver.run(last ? budget : std::max(2, budget / 2));
    const double settled = weight_step(features);
    if (settled >= opt.alternating_converge && converged) break;
  }
  for (WindowFeature* f : features) {
    f->weight_prev = f->weight;
    ++f->times_solved;
  }
}

}  // namespace

SolveStats WindowOptimizer::solve(WindowState& s, int newest, WindowFeatures& features,
                                  const ImuPathFromRest* rest_path) {
  SolveStats st;
  const auto t_ba = Clock::now();
  const WindowGauge gauge = WindowGauge::of(s);
  WindowProblem window(s, newest, features, opt_, prior_, prior_blocks_);
  st.features_in_window = static_cast<int>(window.features().size());
  StateSolver solver(window.problem(), opt_, st);
  if (opt_.loss == BaLoss::Dynavins) {
    const CameraPose* past_frame = features.max_past() > 0 ? &features.past_frame() : nullptr;
    alternate(s, newest, window.features(), opt_, rest_path, past_frame, solver, st);
  } else {
    solver.run(solver.iterations_left());  // eq. 1, Huber loss on the visual residuals
  }
  gauge.restore(s, newest);
  st.ba_ms = ms_since(t_ba);
  return st;
}

void WindowOptimizer::marginalize_oldest(WindowState& s, int newest, WindowFeatures& features) {
  auto info = std::make_shared<MarginalizationInfo>();
  double* pose0 = s.pose[0].data();
  double* sb0 = s.speed_bias[0].data();
  if (prior_) {
    std::vector<int> drop;
    for (size_t b = 0; b < prior_blocks_.size(); ++b) {
      if (prior_blocks_[b] == pose0 || prior_blocks_[b] == sb0) drop.push_back(static_cast<int>(b));
    }
    info->add({std::make_shared<MarginalizationFactor>(prior_), nullptr, prior_blocks_, drop});
  }
  if (imu_usable(s, 1)) {
    info->add({std::make_shared<ImuFactor>(s.preint[1].get(), opt_.gravity), nullptr,
               {pose0, sb0, s.pose[1].data(), s.speed_bias[1].data()}, {0, 1}});
  }
  if (s.still[0]) info->add({std::make_shared<ZeroVelocityFactor>(opt_.zero_velocity_sigma), nullptr, {sb0}, {0}});
  if (!prior_ && opt_.acc_bias_prior_sigma > 0)
    info->add({std::make_shared<AccBiasPriorFactor>(opt_.acc_bias_prior_sigma), nullptr, {sb0}, {0}});
  for (auto& [id, f] : features.all()) {
    if (f.start_slot != 0 || !f.in_ba()) continue;
    // A feature the robust BA rejected would poison the prior forever (paper III; margin_feature_thresh).
    // So would a mono track the state step left out for want of parallax (ŵ = 0, depth_unobservable).
    if (opt_.loss == BaLoss::Dynavins && (f.weight < opt_.margin_feature_thresh || f.state_weight == 0.0)) continue;
    for (VisualResidual& r : visual_residuals(s, f, opt_)) {
      std::vector<int> drop{static_cast<int>(r.blocks.size()) - 1};  // the inverse depth
      if (r.anchor_block >= 0) drop.push_back(r.anchor_block);
      info->add({r.cost, loss_for(r, opt_), r.blocks, drop});
    }
  }
  info->linearize();  // evaluates now, while the features' weights are alive
  if (!marginalize_or_drop(*info)) return;
  std::unordered_map<const double*, double*> shift;
  for (int k = 1; k <= newest; ++k) {
    shift[s.pose[k].data()] = s.pose[k - 1].data();
    shift[s.speed_bias[k].data()] = s.speed_bias[k - 1].data();
  }
  prior_blocks_ = info->kept_blocks(shift);
  prior_ = info;
}

void WindowOptimizer::marginalize_second_newest(WindowState& s, int newest) {
  if (!prior_) return;
  double* pose_drop = s.pose[newest - 1].data();
  std::vector<int> drop;
  for (size_t b = 0; b < prior_blocks_.size(); ++b) {
    if (prior_blocks_[b] == pose_drop) drop.push_back(static_cast<int>(b));
  }
  if (drop.empty()) return;  // the prior does not involve that frame: nothing to do
  auto info = std::make_shared<MarginalizationInfo>();
  info->add({std::make_shared<MarginalizationFactor>(prior_), nullptr, prior_blocks_, drop});
  info->linearize();
  if (!marginalize_or_drop(*info)) return;
  std::unordered_map<const double*, double*> shift;
  shift[s.pose[newest].data()] = s.pose[newest - 1].data();
  shift[s.speed_bias[newest].data()] = s.speed_bias[newest - 1].data();
  prior_blocks_ = info->kept_blocks(shift);
  prior_ = info;
}

}  // namespace dynavins::estimator
