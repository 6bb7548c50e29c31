// A crowded street and its static twin (tests/data/scenarios/street_crowd_short.yaml and
// street_static_short.yaml: the same world, noise seed and 12 s path at 3 m/s; issue 23), through the
// shipped chain (run_vio_sequential, rate 0: iteration-bound, so the same answer on any machine).
// What it checks: where nothing moves, few static features rejected and dynavins' ATE within a bound of
// Huber's (the goal, no cost at all, is not reached yet: README, "Street scenes"); in the crowd,
// the moving features rejected, an ATE close to its own static twin's and far below Huber's. The bounds
// are ratios between runs of the same binary with margins for the noise of one draw, not measured values.
// Measured when written (Release): static twin dynavins 0.045 m, huber 0.028 m, 4.3 % of 1571 static
// features rejected; crowd dynavins 0.033 m, no reset, 97.2 % of 654 moving features rejected, huber
// 8.5 m with 4 resets.
#include "tests/vio/scene_run.hpp"

#include "eval/evaluation.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins;

namespace {

// Issue 23's goals, with a margin where one 12 s noise draw moves the ratio (see the file comment).
// The static twin's bound is NOT the goal (1.0x huber): the defaults cost 1.36x on the long
// street_none and 1.59x here when written (0.045 vs 0.028 m; README, "Street scenes"); this bound only
// catches a larger regression.
constexpr double kStillMargin = 2.0;         // static twin: dynavins ATE <= this x huber's
constexpr double kMaxStaticRejected = 0.05;  // static twin: share of static features with weight < 0.5
constexpr double kMinMovingRejected = 0.85;  // crowd: share of moving features with weight < 0.5
constexpr double kDegradationBound = 1.5;    // crowd / static twin, dynavins (goal 1.2)
constexpr double kHuberRatio = 0.2;          // crowd: dynavins ATE <= this x huber's unless huber reset

using Outcome = test::SceneRun;

Outcome run_scene(const std::shared_ptr<const sim::Scenario>& sc, estimator::BaLoss loss) {
  return test::run_scene(sc, loss);
}

std::shared_ptr<const sim::Scenario> scene(const std::string& name) {
  return sim::build_scenario(
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/tests/data/scenarios/" + name + ".yaml"));
}

/// The estimated path length against the true one over the same frames (a scale without an alignment),
/// over the frames in [from_s, to_s] (seconds, the clock of the estimates) when given.
double length_ratio(const Outcome& o, double from_s = -1e18, double to_s = 1e18) {
  double est = 0.0, truth = 0.0;
  const auto& p = o.run.estimate.poses;
  for (std::size_t i = 1; i < p.size(); ++i) {
    const double t = 1e-9 * static_cast<double>(p[i - 1].t_ns);
    if (t < from_s || 1e-9 * static_cast<double>(p[i].t_ns) > to_s) continue;
    est += (p[i].p - p[i - 1].p).norm();
    const auto v = o.true_speed.lower_bound(p[i].t_ns);
    if (v != o.true_speed.end()) truth += v->second * 1e-9 * static_cast<double>(p[i].t_ns - p[i - 1].t_ns);
  }
  return est / truth;
}

}  // namespace

TEST_CASE("street twins: the robust BA keeps the static street and holds in the crowd",
          "[vio][dynamic][street]") {
  const auto still = scene("street_static_short");
  const Outcome dyn_still = run_scene(still, estimator::BaLoss::Dynavins);
  const Outcome hub_still = run_scene(still, estimator::BaLoss::Huber);
  INFO("static twin: dynavins ATE " << dyn_still.ate << " m, huber " << hub_still.ate << " m");
  REQUIRE(dyn_still.run.resets == 0);
  REQUIRE(hub_still.run.resets == 0);
  CHECK(dyn_still.run.tracking_frames >= 0.9 * dyn_still.run.frames);
  // No cost when nothing moves: within Huber's ATE (with the margin of one noise draw).
  CHECK(dyn_still.ate <= kStillMargin * hub_still.ate);
  const eval::WeightScore still_score = eval::score_weights(dyn_still.run.features);
  REQUIRE(still_score.stationary > 100);
  CHECK(still_score.moving == 0);
  CHECK(1.0 - still_score.static_kept < kMaxStaticRejected);

  const auto crowd = scene("street_crowd_short");
  const Outcome dyn_crowd = run_scene(crowd, estimator::BaLoss::Dynavins);
  const Outcome hub_crowd = run_scene(crowd, estimator::BaLoss::Huber);
  INFO("crowd: dynavins ATE " << dyn_crowd.ate << " m (resets " << dyn_crowd.run.resets << "), huber "
                              << hub_crowd.ate << " m (resets " << hub_crowd.run.resets << ")");
  CHECK(dyn_crowd.run.resets == 0);
  CHECK(dyn_crowd.run.tracking_frames >= 0.9 * dyn_crowd.run.frames);
  const eval::WeightScore crowd_score = eval::score_weights(dyn_crowd.run.features);
  REQUIRE(crowd_score.moving > 50);  // the vehicles were seen and went through the BA
  CHECK(crowd_score.moving_rejected >= kMinMovingRejected);
  // Degradation against its own static twin, and far below the baseline.
  CHECK(dyn_crowd.ate <= kDegradationBound * dyn_still.ate);
  CHECK((hub_crowd.run.resets > 0 || dyn_crowd.ate <= kHuberRatio * hub_crowd.ate));
}

TEST_CASE("mono initialises behind a truck that leads the camera", "[vio][dynamic][street][mono]") {
  // bench/scenarios/street_follow.yaml and its static twin, first 6 s: the car starts from rest at
  // t = 1 s and reaches 3 m/s; a box truck's rear stays ~3 m ahead, about half the image. Its features
  // keep their pixels while the camera drives, so averaged into VINS-Fusion's parallax test they kept
  // the mono initialisation from ever succeeding (38 s, 0 % tracking; issue 23). Judged on the features
  // that move in the image (MonoSfmOptions::min_feature_motion_px), it initialises as soon as the static
  // twin does. Measured when written: both at t = 2.8 s; path length / true 1.034 behind the truck,
  // 1.042 in the twin (bound: 10 %); from the longer initialisation spans (stop 51) 1.010 / 1.007.
  const auto first_6s = [](const std::string& name) {
    return sim::build_scenario(
        sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/" + name + ".yaml"), std::nullopt,
        6.0);
  };
  const Outcome twin = test::run_scene(first_6s("street_follow_none"), estimator::BaLoss::Dynavins, false);
  const Outcome truck = test::run_scene(first_6s("street_follow"), estimator::BaLoss::Dynavins, false);
  REQUIRE_FALSE(twin.run.estimate.poses.empty());
  REQUIRE_FALSE(truck.run.estimate.poses.empty());
  const double t0 = 1e-9 * static_cast<double>(truck.true_speed.begin()->first);
  const double twin_init = 1e-9 * static_cast<double>(twin.run.estimate.poses.front().t_ns) - t0;
  const double truck_init = 1e-9 * static_cast<double>(truck.run.estimate.poses.front().t_ns) - t0;
  // Scale after initialisation (the first 6 s are a straight line, too degenerate for an aligned ATE).
  const double truck_scale = length_ratio(truck), twin_scale = length_ratio(twin);
  INFO("initialised at t = " << truck_init << " s behind the truck, " << twin_init << " s in the static twin; "
                             << "path length / true " << truck_scale << " / " << twin_scale);
  CHECK(truck.run.resets == 0);
  CHECK(truck_init <= twin_init + 1.0);
  CHECK(std::abs(truck_scale - 1.0) < 0.1);
}

TEST_CASE("mono takes the initial scale from the whole start from rest", "[vio][street][mono]") {
  // bench/scenarios/street_none.yaml, first 6 s: the car starts from rest at t = 1 s and reaches 3 m/s at
  // ~3.2 s. The latest 11 frames (0.5 s) pass the parallax test at ~2.85 s, where the acceleration is
  // nearly constant: its free gravity tilts to absorb it and their scale came out at 0.58-0.78 of the
  // truth on six draws; the window solve pulls it in over seconds, and the first 24 m stayed 1-4 % long.
  // One frame in 4 of the last 41 (2 s) holds the start of the acceleration: its scale is the more
  // certain one and the window starts from it (mono_init_wide_window). Measured when written: path
  // length / true over the first second tracked 1.000 with it, 1.096 without (the window solve overshoots
  // from the low start), both at t = 2.8 s (bound: 10 % of 1, and closer than without).
  const auto street = sim::build_scenario(
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/street_none.yaml"), std::nullopt, 6.0);
  const Outcome latest = test::run_scene(street, estimator::BaLoss::Dynavins, false,
                                         [](EstimatorOptions& o) { o.mono_init_wide_window = false; });
  const Outcome longest = test::run_scene(street, estimator::BaLoss::Dynavins, false);
  REQUIRE_FALSE(latest.run.estimate.poses.empty());
  REQUIRE_FALSE(longest.run.estimate.poses.empty());
  const auto first_second = [](const Outcome& o) {
    const double t = 1e-9 * static_cast<double>(o.run.estimate.poses.front().t_ns);
    return length_ratio(o, t, t + 1.0);
  };
  const double with = first_second(longest), without = first_second(latest);
  INFO("path length / true over the first second tracked: " << with << " from the longer span, " << without
                                                            << " from the latest 11 frames");
  CHECK(longest.run.resets == 0);
  CHECK(std::abs(with - 1.0) < 0.1);
  CHECK(std::abs(with - 1.0) < std::abs(without - 1.0));
}

TEST_CASE("mono initialises at night when its first windows have parallax but no scale",
          "[vio][street][mono]") {
  // bench/scenarios/street_crowd_night.yaml at noise seed 22, first 6 s: the car starts from rest at
  // t = 1 s. The latest 11 frames (0.5 s) reach the parallax test only at 2.85 s, late in the
  // acceleration, and their scale is too uncertain from then on (then the car cruises: no excitation);
  // at full length this draw did not initialise until 47.95 s (issue 23). After 10 such windows in a
  // row, one frame in 2-4 of the last 21-41 (1-2 s, mono_init_wide_window) holds more of the acceleration.
  // Measured when written: initialised at t = 3.3 s with it (the first such try; bound 4 s), never in
  // these 6 s without; path length / true 0.979 (bound: 15 %); with strides 3 and 4 tried too (stop 51)
  // one frame in 3 of the last 31, 1.008.
  const auto night = sim::build_scenario(
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/street_crowd_night.yaml"), 22, 6.0);
  const Outcome narrow = test::run_scene(night, estimator::BaLoss::Dynavins, false,
                                         [](EstimatorOptions& o) { o.mono_init_wide_window = false; });
  const Outcome wide = test::run_scene(night, estimator::BaLoss::Dynavins, false);
  REQUIRE_FALSE(wide.run.estimate.poses.empty());
  const double t0 = 1e-9 * static_cast<double>(wide.true_speed.begin()->first);
  const double init = 1e-9 * static_cast<double>(wide.run.estimate.poses.front().t_ns) - t0;
  const double scale = length_ratio(wide);
  INFO("initialised at t = " << init << " s; path length / true " << scale << "; without the wide window "
                             << narrow.run.estimate.poses.size() << " frames estimated");
  CHECK(wide.run.resets == 0);
  CHECK(init < 4.0);
  CHECK(std::abs(scale - 1.0) < 0.15);
  // The draw still shows the failure this guards against (if the simulator changes, pick another draw).
  CHECK(narrow.run.estimate.poses.empty());
}

TEST_CASE("stereo: a truck that drives off with the camera does not take the estimate with it",
          "[vio][dynamic][street][zupt_imu]") {
  // bench/scenarios/street_follow.yaml at noise seed 26, first 6 s: the car stands still until ~0.6 s with
  // a box truck's rear 3 m ahead (half the image), then both drive off together. At rest every track fits,
  // and the truck's then keep their pixels: the image test kept calling the car still (holding v = 0) and
  // the joint solve followed the truck (path length 0.28-0.7 of the truth's over 1-3 s, the static tracks
  // rejected, 0.55 m ATE over the whole run; issue 23). zupt_imu: the IMU's velocity must agree with a
  // standstill, and once the solve leaves the IMU's path from the last rest frame the weights are judged
  // on that path. Measured when written: path length / true over the drive-off (1-3 s) 0.975 with it,
  // 0.586 without (bounds: 10 % / the failure still shown); 97.4 % of the moving features rejected.
  // rejected_feedback (on by default) must not feed back the verdicts judged on that IMU path: they reject
  // most of the static scene for ~2 s (the path drifts with the accelerometer bias), and fed back they
  // steered fresh corners onto the truck: 38 of 120 truck tracks ended kept (68 % rejected); 96 % with it.
  // Without zupt_imu there is no such path, and the feedback deepens the failure: ratio 0.074 (0.586 off).
  const auto drive_off = sim::build_scenario(
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/street_follow.yaml"), 26, 6.0);
  const Outcome with = test::run_scene(drive_off, estimator::BaLoss::Dynavins);
  const Outcome without = test::run_scene(drive_off, estimator::BaLoss::Dynavins, true,
                                          [](EstimatorOptions& o) { o.zupt_imu = false; });
  REQUIRE_FALSE(with.run.estimate.poses.empty());
  const double t0 = 1e-9 * static_cast<double>(with.true_speed.begin()->first);
  const auto drive_off_ratio = [t0](const Outcome& o) { return length_ratio(o, t0 + 1.0, t0 + 3.0); };
  const double ratio_with = drive_off_ratio(with), ratio_without = drive_off_ratio(without);
  const eval::WeightScore score = eval::score_weights(with.run.features);
  INFO("path length / true over 1-3 s: " << ratio_with << " with zupt_imu, " << ratio_without
                                         << " without; moving rejected " << score.moving_rejected << " of " << score.moving);
  CHECK(with.run.resets == 0);
  CHECK(std::abs(ratio_with - 1.0) < 0.1);
  CHECK(score.moving_rejected >= kMinMovingRejected);
  // The draw still shows the failure this guards against (if the simulator changes, pick another draw).
  CHECK(ratio_without < 0.9);
}
