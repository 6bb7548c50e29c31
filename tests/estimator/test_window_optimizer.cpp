// WindowOptimizer (the robust BA of paper III) on a small synthetic window with known ground truth: 11
// slots on a smooth 6-DoF path with exact (noise-free) preintegrated IMU, stereo observations of static
// points (0.1 px noise) and of points that move 0.3-0.8 m between frames. Checks the alternation's
// weights (III-C, eq. 10-11), the huber baseline, the momentum of eq. 9, the solved poses, and that a
// rejected feature stays out of the marginalisation prior (margin_feature_thresh).
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <Eigen/Geometry>

#include "stages/common/so3.hpp"
#include "stages/estimator/marginalization/marginalization_info.hpp"
#include "stages/estimator/window_optimizer.hpp"
#include "tests/estimator/test_initialization_scenario.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

/// Observation noise at the nominal focal length (460 px). The anchor's own noise enters every residual
/// of its track, so a static feature's r_j comes out at up to about 5 (σ / 1.5 px)² (0.05 here: w_j > 0.95).
constexpr double kNoisePx = 0.1;
constexpr double kBaseline = 0.11;  ///< m, cam1 along cam0's x

struct WindowSetup {
  int static_features = 40;
  int moving_features = 12;
  double pose_offset_m = 0.01;     ///< start of the solve: slots 1.. displaced by about this much
  double pose_offset_deg = 0.1;    ///< and rotated by about this much
  int times_solved = 0;            ///< n_j of every feature (w̄_j = 1)
  uint64_t seed = 11;
  bool mono = false;                ///< no right observations
  double static_depth_scale = 1.0;  ///< static points at 3-10 m times this
  /// Points that translate with the camera (a truck leading it at its speed), seen in every slot; made last.
  int riders = 0;
  /// Points that move 0.3 m per frame across the view until slot kStopSlot and stand still from then on,
  /// seen in every slot; made after the riders.
  int stoppers = 0;
  static constexpr int kStopSlot = 5;
};

/// A window with its ground truth. Slot 0 starts at the truth; the gauge (position and yaw of slot 0)
/// keeps it there, so the solved poses compare directly with the truth.
struct SyntheticWindow {
  static constexpr int kWindowSize = 10;
  explicit SyntheticWindow(const WindowSetup& setup);

  int newest() const { return kWindowSize; }
  bool moving(int64_t id) const { return moving_ids.count(id) > 0; }
  /// Largest position [m] and rotation [deg] error over the slots.
  double max_position_error() const {
    double e = 0;
    for (int k = 0; k <= newest(); ++k) e = std::max(e, (state.p(k) - p_true[k]).norm());
    return e;
  }
  double max_rotation_error_deg() const {
    double e = 0;
    for (int k = 0; k <= newest(); ++k)
      e = std::max(e, Eigen::AngleAxisd(q_true[k].conjugate() * state.q(k)).angle() * 180.0 / M_PI);
    return e;
  }

  test::Scenario scenario;
  WindowState state{kWindowSize};
  WindowFeatures features;
  std::vector<Eigen::Vector3d> p_true;
  std::vector<Eigen::Quaterniond> q_true;
  std::set<int64_t> moving_ids;
};

SyntheticWindow::SyntheticWindow(const WindowSetup& setup) {
  test::ScenarioOptions so;
  so.landmarks = 0;  // the features are made here, with stereo and moving points
  so.gyro_bias.setZero();
  scenario = test::make_scenario(so);
  REQUIRE(scenario.frames() == kWindowSize + 1);

  const Eigen::Quaterniond q_bc(scenario.R_bc);
  const Eigen::Vector3d p_bc1 = scenario.p_bc + scenario.R_bc * Eigen::Vector3d(kBaseline, 0, 0);
  state.extrinsic[0] = {scenario.p_bc.x(), scenario.p_bc.y(), scenario.p_bc.z(), q_bc.x(), q_bc.y(), q_bc.z(), q_bc.w()};
  state.extrinsic[1] = {p_bc1.x(), p_bc1.y(), p_bc1.z(), q_bc.x(), q_bc.y(), q_bc.z(), q_bc.w()};

  std::mt19937_64 rng(setup.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k <= kWindowSize; ++k) {
    const sim::KinematicState& x = scenario.truth[k];
    p_true.push_back(x.p_w);
    q_true.push_back(Eigen::Quaterniond(x.R_wb).normalized());
    state.t_ns[k] = static_cast<int64_t>(std::llround(scenario.t[k] * 1e9));
    state.v(k) = x.v_w;
    if (k > 0) state.preint[k] = std::make_unique<imu::ImuPreintegration>(*scenario.preints[k - 1]);
    Eigen::Vector3d dp = Eigen::Vector3d::Zero(), dtheta = Eigen::Vector3d::Zero();
    if (k > 0) {
      dp = setup.pose_offset_m / std::sqrt(3.0) * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      dtheta = setup.pose_offset_deg * M_PI / 180.0 / std::sqrt(3.0) * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    }
    state.p(k) = x.p_w + dp;
    state.q(k) = (q_true[k] * Eigen::Quaterniond(so3::exp(dtheta))).normalized();
  }

  // Projection of a world point into cam c at slot k on the z = 1 plane, false when not in the image.
  auto project = [&](const Eigen::Vector3d& p_w, int k, int c, Eigen::Vector2d& xy) {
    const Eigen::Matrix3d R_wc = scenario.truth[k].R_wb * scenario.R_bc;
    const Eigen::Vector3d p_wc = scenario.truth[k].p_w + scenario.truth[k].R_wb * (c == 0 ? scenario.p_bc : p_bc1);
    const Eigen::Vector3d p_c = R_wc.transpose() * (p_w - p_wc);
    if (p_c.z() < 1.0) return false;
    xy = p_c.head<2>() / p_c.z();
    return std::abs(xy.x()) < 0.8 && std::abs(xy.y()) < 0.6;
  };
  const double sigma = kNoisePx / kNominalFocalPx;
  // A track of a point at `point(k)` in slots start..end; false (nothing added) if it leaves the image.
  auto addTrack = [&](int64_t id, int start, int end, const auto& point) {
    WindowFeature f;
    f.id = id;
    f.start_slot = start;
    for (int k = start; k <= end; ++k) {
      FeatureObservation o;
      if (!project(point(k), k, 0, o.xy) || (!setup.mono && !project(point(k), k, 1, o.xy_right))) return false;
      o.xy += sigma * Eigen::Vector2d(n01(rng), n01(rng));
      o.xy_right += sigma * Eigen::Vector2d(n01(rng), n01(rng));
      o.has_right = !setup.mono;
      f.obs.push_back(o);
    }
    // Depth as stereo triangulation in the anchor would give it (within a few percent).
    const Eigen::Matrix3d R_wc = scenario.truth[start].R_wb * scenario.R_bc;
    const double z = (R_wc.transpose() * (point(start) - (scenario.truth[start].p_w + scenario.truth[start].R_wb * scenario.p_bc))).z();
    f.inv_depth = 1.0 / (z * (1.0 + 0.03 * u(rng)));
    f.has_depth = true;
    f.times_solved = setup.times_solved;
    features.all()[id] = f;
    return true;
  };

  const int mid = kWindowSize / 2;
  const Eigen::Matrix3d R_mid = scenario.R_wc(mid);
  const Eigen::Vector3d p_mid = scenario.p_wc(mid);
  int64_t id = 0;
  for (int made = 0; made < setup.static_features;) {
    // 3-10 m ahead of the middle camera; anchored in slots 0-3, seen to the newest slot.
    const double z = setup.static_depth_scale * (3.0 + 7.0 * 0.5 * (u(rng) + 1.0));
    const Eigen::Vector3d p_w = R_mid * Eigen::Vector3d(0.6 * u(rng) * z, 0.4 * u(rng) * z, z) + p_mid;
    const int start = made % 4;
    if (addTrack(id, start, kWindowSize, [&p_w](int) { return p_w; })) ++made;
    ++id;
  }
  for (int made = 0; made < setup.moving_features;) {
    // 5-9 m ahead, crossing the view at 0.3-0.8 m per frame for 4-6 frames.
    const int length = 4 + made % 3;
    const int start = static_cast<int>(std::uniform_int_distribution<int>(0, kWindowSize + 1 - length)(rng));
    const Eigen::Matrix3d R_a = scenario.R_wc(start);
    const double z = 7.0 + 2.0 * u(rng);
    const double side = u(rng) > 0 ? 1.0 : -1.0;
    const Eigen::Vector3d p0 = R_a * Eigen::Vector3d(-side * 0.3 * z, 0.3 * u(rng) * z, z) + scenario.p_wc(start);
    const double speed = 0.3 + 0.5 * 0.5 * (u(rng) + 1.0);
    const Eigen::Vector3d step = speed * (R_a * Eigen::Vector3d(side, 0.2 * u(rng), 0.2 * u(rng))).normalized();
    if (addTrack(id, start, start + length - 1, [&](int k) { return Eigen::Vector3d(p0 + (k - start) * step); })) {
      moving_ids.insert(id);
      ++made;
    }
    ++id;
  }
  for (int made = 0; made < setup.riders;) {
    // 3-4 m ahead of the first camera, then moved with the camera's position (not its rotation): exactly
    // what a point at infinity looks like.
    const Eigen::Vector3d offset = scenario.R_wc(0) * Eigen::Vector3d(0.5 * u(rng), 0.3 * u(rng), 3.5 + 0.5 * u(rng));
    if (addTrack(id, 0, kWindowSize, [&](int k) { return Eigen::Vector3d(scenario.p_wc(k) + offset); })) {
      moving_ids.insert(id);
      ++made;
    }
    ++id;
  }
  for (int made = 0; made < setup.stoppers;) {
    const Eigen::Vector3d stop = scenario.R_wc(0) * Eigen::Vector3d(0.8 * u(rng), 0.5 * u(rng), 5.0 + u(rng)) + scenario.p_wc(0);
    const Eigen::Vector3d step = 0.3 * (scenario.R_wc(0) * Eigen::Vector3d(u(rng) > 0 ? 1.0 : -1.0, 0.3 * u(rng), 0.0)).normalized();
    const auto point = [&](int k) { return Eigen::Vector3d(stop - std::max(0, WindowSetup::kStopSlot - k) * step); };
    if (addTrack(id, 0, kWindowSize, point)) {
      moving_ids.insert(id);
      ++made;
    }
    ++id;
  }
}

WindowSolveOptions solve_options(BaLoss loss) {
  WindowSolveOptions o;
  o.loss = loss;
  o.stereo = true;
  // Deterministic: no time budget (results must not depend on the machine or on ThreadSanitizer).
  o.max_solver_time_s = std::numeric_limits<double>::infinity();
  return o;
}

}  // namespace

TEST_CASE("dynavins BA keeps static features, rejects moving ones and stays on the true path",
          "[estimator][window_optimizer]") {
  SyntheticWindow w(WindowSetup{});
  WindowOptimizer optimizer(solve_options(BaLoss::Dynavins));
  const double start_error = w.max_position_error();
  const SolveStats st = optimizer.solve(w.state, w.newest(), w.features);

  CHECK(st.features_in_window == 52);
  CHECK(st.alternations >= 2);  // at least one weight step after a state solve
  CHECK(st.ceres_iterations <= optimizer.options().max_iterations);
  double min_static = 1.0, max_moving = 0.0;
  for (const auto& [id, f] : w.features.all()) {
    INFO("feature " << id << (w.moving(id) ? " (moving)" : " (static)") << " weight " << f.weight);
    if (w.moving(id)) {
      CHECK(f.weight < 0.5);
      max_moving = std::max(max_moving, f.weight);
    } else {
      CHECK(f.weight > 0.9);
      min_static = std::min(min_static, f.weight);
    }
    // The weight after the solve becomes w̄_j of the next one, and n_j counts the solve.
    CHECK(f.weight_prev == f.weight);
    CHECK(f.times_solved == 1);
  }
  // Near the truth (what the noise allows: about 4 mm, 0.07 deg), and where the same window without the
  // moving points ends up (huber is dragged 0.26 m by them, next test).
  SyntheticWindow static_only([] {
    WindowSetup setup;
    setup.moving_features = 0;  // same static observations and start (same seed, drawn first)
    return setup;
  }());
  WindowOptimizer(solve_options(BaLoss::Dynavins)).solve(static_only.state, static_only.newest(), static_only.features);
  double from_static_only = 0;
  for (int k = 0; k <= w.newest(); ++k)
    from_static_only = std::max(from_static_only, (w.state.p(k) - static_only.state.p(k)).norm());
  INFO("start error " << start_error << " m; solved " << w.max_position_error() << " m, " << w.max_rotation_error_deg()
                      << " deg, " << from_static_only << " m from the solve without moving points; static weights >= "
                      << min_static << ", moving <= " << max_moving);
  CHECK(w.max_position_error() < 0.01);
  CHECK(w.max_rotation_error_deg() < 0.15);
  CHECK(from_static_only < 0.002);
}

TEST_CASE("huber BA leaves every weight at 1", "[estimator][window_optimizer]") {
  SyntheticWindow w(WindowSetup{});
  WindowOptimizer optimizer(solve_options(BaLoss::Huber));
  const SolveStats st = optimizer.solve(w.state, w.newest(), w.features);
  CHECK(st.alternations == 1);
  CHECK(st.features_in_window == 52);
  for (const auto& [id, f] : w.features.all()) {
    INFO("feature " << id);
    CHECK(f.weight == 1.0);
    CHECK(f.weight_prev == 1.0);
    CHECK(f.times_solved == 0);
  }
  // Unweighted, the moving points do pull the solve off the path (0.26 m): the scene tests something.
  INFO("solved " << w.max_position_error() << " m, " << w.max_rotation_error_deg() << " deg");
  CHECK(w.max_position_error() > 0.05);
}

TEST_CASE("momentum (eq. 9-10): a feature's weight moves more slowly the more often it was solved",
          "[estimator][window_optimizer]") {
  // The same window twice, every feature with w̄_j = 1: never solved (n_j = 0) and solved 5 times. With
  // λm = 0.2 the moving features' weights come down less far in one solve when n_j = 5 (for a large r_j
  // about (λw + 25 λm) / λw = 6 times higher); with λm = 0 n_j does not matter at all.
  for (const double lambda_m : {0.2, 0.0}) {
    INFO("lambda_m " << lambda_m);
    WindowSolveOptions o = solve_options(BaLoss::Dynavins);
    o.weights.lambda_m = lambda_m;
    WindowSetup seasoned_setup;
    seasoned_setup.times_solved = 5;
    SyntheticWindow fresh(WindowSetup{}), seasoned(seasoned_setup);
    WindowOptimizer(o).solve(fresh.state, fresh.newest(), fresh.features);
    WindowOptimizer(o).solve(seasoned.state, seasoned.newest(), seasoned.features);
    for (const auto& [id, f] : fresh.features.all()) {
      const WindowFeature& g = seasoned.features.all().at(id);
      INFO("feature " << id << (fresh.moving(id) ? " (moving)" : " (static)") << ": weight " << f.weight
                      << " with n_j = 0, " << g.weight << " with n_j = 5");
      CHECK(g.times_solved == 6);
      if (!fresh.moving(id)) {
        CHECK(f.weight > 0.9);
        CHECK(g.weight > 0.9);
      } else if (lambda_m > 0) {
        CHECK(f.weight < 0.5);
        CHECK(g.weight > 3.0 * f.weight);
      } else {
        CHECK(f.weight < 0.5);
        CHECK(g.weight == f.weight);
      }
    }
  }
}

TEST_CASE("a feature the robust BA rejected (weight < margin_feature_thresh) stays out of the prior",
          "[estimator][window_optimizer]") {
  SyntheticWindow w(WindowSetup{});
  // The first static feature anchored in slot 0: it leaves the window with the oldest keyframe.
  int64_t leaving = -1;
  for (const auto& [id, f] : w.features.all()) {
    if (f.start_slot == 0 && !w.moving(id)) {
      leaving = id;
      break;
    }
  }
  REQUIRE(leaving >= 0);
  // The prior's information H* = J^T J and gradient b* = J^T r0 after marginalising slot 0 with the
  // leaving feature at `weight`, or without it (weight < 0).
  struct Prior {
    std::vector<double*> blocks;
    Eigen::MatrixXd H;
    Eigen::VectorXd b;
  };
  auto priorWith = [&](BaLoss loss, double weight) {
    WindowFeatures features = w.features;
    if (weight < 0) {
      features.all().erase(leaving);
    } else {
      features.all().at(leaving).weight = weight;
    }
    WindowOptimizer optimizer(solve_options(loss));
    optimizer.marginalize_oldest(w.state, w.newest(), features);
    REQUIRE(optimizer.has_prior());
    const MarginalizationInfo& info = *optimizer.prior();
    const Eigen::MatrixXd& J = info.linearized_jacobian();
    return Prior{info.kept_blocks(), J.transpose() * J, J.transpose() * info.linearized_residual()};
  };
  auto relativeDifference = [](const Prior& a, const Prior& b) {
    REQUIRE(a.blocks == b.blocks);
    return std::max((a.H - b.H).cwiseAbs().maxCoeff() / a.H.cwiseAbs().maxCoeff(),
                    (a.b - b.b).cwiseAbs().maxCoeff() / std::max(1.0, a.b.cwiseAbs().maxCoeff()));
  };

  const Prior without = priorWith(BaLoss::Dynavins, -1.0);
  const Prior rejected = priorWith(BaLoss::Dynavins, 0.05);
  const Prior kept = priorWith(BaLoss::Dynavins, 0.9);
  CHECK(relativeDifference(rejected, without) < 1e-12);
  CHECK(relativeDifference(kept, without) > 1e-3);
  // Huber ignores the weights: the same feature is part of its prior.
  CHECK(relativeDifference(priorWith(BaLoss::Huber, 0.05), priorWith(BaLoss::Huber, -1.0)) > 1e-3);
}

TEST_CASE(
    "mono: a track that keeps its bearing while the camera drives stays out of the state step "
    "(mono_max_depth_baselines)",
    "[estimator][window_optimizer]") {
  // Points riding with the camera (a truck leading it) fit a point at infinity within the noise, so eq. 10
  // keeps them; the static points, 3-10 m away, show the parallax of the window's baseline. The state step
  // weight ŵ_j is what the reprojection factors and the prior read.
  WindowSetup setup;
  setup.mono = true;
  setup.moving_features = 0;
  setup.riders = 15;
  for (const double k : {30.0, 0.0}) {
    INFO("mono_max_depth_baselines " << k);
    SyntheticWindow w(setup);
    WindowSolveOptions o = solve_options(BaLoss::Dynavins);
    o.stereo = false;
    o.mono_max_depth_baselines = k;
    WindowOptimizer(o).solve(w.state, w.newest(), w.features);
    int riders = 0, riders_kept = 0;
    for (const auto& [id, f] : w.features.all()) {
      INFO("feature " << id << (w.moving(id) ? " (rider)" : " (static)") << " weight " << f.weight
                      << ", state step weight " << f.state_weight);
      if (!w.moving(id)) {
        CHECK(f.weight > 0.9);
        CHECK(f.state_weight > 0.9);
      } else {
        ++riders;
        riders_kept += f.state_weight > 0.5;
        if (k > 0) CHECK(f.state_weight == 0.0);
      }
    }
    CHECK(riders == setup.riders);
    // Without the rule some pass for points at infinity (the others' BA depth went behind the camera in the
    // first state solve, where the weight step's depth fit cannot follow, and eq. 10 rejects them).
    if (k == 0) CHECK(riders_kept > 0);
  }
}

TEST_CASE("mono: a track whose past keyframes contradict the static point its window fits stays out of the "
          "state step (mono_history_keyframes)",
          "[estimator][window_optimizer]") {
  // Points that crossed the view and then stood still: within the window left after the first five
  // keyframes slid out they fit a static point (eq. 10 keeps them); with the five in their past they do
  // not. The static tracks' past fits, so they stay in. The slide is the estimator's: the features drop
  // slot 0 into their past with its pose, the states move down a slot.
  WindowSetup setup;
  setup.mono = true;
  setup.moving_features = 0;
  setup.stoppers = 8;
  for (const int history : {16, 0}) {
    INFO("mono_history_keyframes " << history);
    SyntheticWindow w(setup);
    w.features.set_max_past(history);
    int newest = w.newest();
    for (int r = 0; r < WindowSetup::kStopSlot; ++r) {
      w.features.remove_oldest([&w](int k) { return w.state.camera(k, 0); }, true);
      for (int k = 0; k < newest; ++k) w.state.move_slot(k + 1, k);
      w.state.preint[0].reset();
      --newest;
    }
    WindowSolveOptions o = solve_options(BaLoss::Dynavins);
    o.stereo = false;
    WindowOptimizer(o).solve(w.state, newest, w.features);
    int stoppers = 0, stoppers_kept = 0, static_with_past = 0;
    for (const auto& [id, f] : w.features.all()) {
      INFO("feature " << id << (w.moving(id) ? " (stopped)" : " (static)") << ", " << f.past.size()
                      << " past, weight " << f.weight << ", state step weight " << f.state_weight);
      CHECK(static_cast<int>(f.past.size()) <= history);
      if (!w.moving(id)) {
        static_with_past += !f.past.empty();
        CHECK(f.state_weight > 0.9);
      } else {
        ++stoppers;
        CHECK(f.past.size() == (history > 0 ? WindowSetup::kStopSlot : 0));
        CHECK(f.weight > 0.5);  // eq. 10 on the window alone keeps it
        stoppers_kept += f.state_weight > 0.5;
      }
    }
    CHECK(stoppers == setup.stoppers);
    if (history > 0) {
      CHECK(static_with_past > 0);
      CHECK(stoppers_kept == 0);
    } else {
      CHECK(stoppers_kept == stoppers);
    }
  }
}

TEST_CASE("mono: where the whole window shows no parallax, nothing is judged by mono_max_depth_baselines",
          "[estimator][window_optimizer]") {
  // The static points 100x farther away (300-1000 m): every track is deeper than 30 baselines, and so is the
  // window's median, so the rule leaves every feature in the state step (a camera at rest is this case: no
  // baseline at all).
  WindowSetup setup;
  setup.mono = true;
  setup.moving_features = 0;
  setup.static_depth_scale = 100.0;
  SyntheticWindow w(setup);
  WindowSolveOptions o = solve_options(BaLoss::Dynavins);
  o.stereo = false;
  REQUIRE(o.mono_max_depth_baselines == 30.0);
  WindowOptimizer(o).solve(w.state, w.newest(), w.features);
  for (const auto& [id, f] : w.features.all()) {
    INFO("feature " << id << " weight " << f.weight << ", state step weight " << f.state_weight);
    CHECK(f.weight > 0.9);
    CHECK(f.state_weight > 0.9);
  }
}
