// The estimator's finished keyframes (WindowEstimate::finished_keyframes, the loop closer's input) through
// the shipped chain (run_vio_sequential, rate 0: deterministic) on a short moving simulator scene: the first
// 6 s of tests/data/scenarios/truck_crossing.yaml without its truck (a drone flying along a street).
// Checks that keyframes leave the window once each, in time order, only frames the window kept, with
// poses close to the simulator's ground truth, triangulated weighted points and the left image.
#include "tests/estimator/catch_with_ceres.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>

#include "eval/evaluation.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins;

TEST_CASE("finished keyframes of a moving scene: once each, in order, kept frames, poses near the truth",
          "[vio][keyframes]") {
  sim::ScenarioSpec spec =
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/tests/data/scenarios/truck_crossing.yaml");
  // 8 s: into the S's first bend. Over the first straight alone the true path is a line, the alignment's
  // rotation about it undefined, and whether Umeyama calls it degenerate was rounding luck.
  spec.duration = 8.0;
  spec.objects.clear();
  const auto sc = sim::build_scenario(spec);
  sim::ScenarioSource src(sc);
  pipeline::VioRunOptions opt;
  opt.estimator = sim::scenario_estimator_options(*sc);
  opt.show_progress = false;

  std::vector<estimator::WindowEstimate> estimates;
  std::vector<Keyframe> keyframes;
  pipeline::EstimateRecorder recorder;
  pipeline::VioSinks sinks;
  sinks.estimate = [&](const estimator::WindowEstimate& e) {
    recorder.record(e);
    estimator::WindowEstimate light = e;
    light.features.features.clear();
    light.finished_keyframes.clear();
    estimates.push_back(std::move(light));
  };
  sinks.keyframe = [&](const Keyframe& kf) { keyframes.push_back(kf); };
  const pipeline::VioRunResult r = pipeline::run_vio_sequential(src, opt, sinks);
  REQUIRE(r.report.ok);
  REQUIRE(r.resets == 0);
  REQUIRE(keyframes.size() >= 10);

  // Once each, in time order; never a frame the window dropped; every kept frame up to the last one out.
  std::set<int64_t> kept, dropped, out;
  for (std::size_t i = 0; i + 1 < estimates.size(); ++i) {
    if (estimates[i].status == estimator::EstimatorStatus::Tracking &&
        estimates[i + 1].status == estimator::EstimatorStatus::Tracking)
      (estimates[i + 1].keyframe ? kept : dropped).insert(estimates[i].t_ns);
  }
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    INFO("keyframe " << k << " at t = " << keyframes[k].t_ns);
    if (k > 0) CHECK(keyframes[k].t_ns > keyframes[k - 1].t_ns);
    CHECK(dropped.count(keyframes[k].t_ns) == 0);
    out.insert(keyframes[k].t_ns);
  }
  for (int64_t t : kept)
    if (t <= keyframes.back().t_ns) CHECK(out.count(t) == 1);

  // Poses: the window's final estimate of each keyframe, against the truth, in the frame the per-frame
  // odometry aligns to (SE(3) Umeyama over all frames: the keyframes alone lie too close to a line).
  const eval::Trajectory gt = pipeline::ground_truth_trajectory(r.ground_truth);
  const eval::EvalResult odo = eval::evaluate(gt, recorder.estimate);
  eval::Trajectory kf_traj;
  for (const Keyframe& kf : keyframes) kf_traj.poses.push_back(eval::stamped_pose(kf.t_ns, kf.p_wb, kf.q_wb));
  const eval::Trajectory kf_aligned = eval::transformed(kf_traj, odo.alignment);
  double sq = 0, worst = 0;
  for (const eval::StampedPose& k : kf_aligned.poses) {
    auto it = std::lower_bound(gt.poses.begin(), gt.poses.end(), k.t_ns,
                               [](const eval::StampedPose& g, int64_t t) { return g.t_ns < t; });
    REQUIRE(it != gt.poses.end());
    REQUIRE(std::llabs(it->t_ns - k.t_ns) < 1'000'000);
    const double e = (it->p - k.p).norm();
    sq += e * e;
    worst = std::max(worst, e);
  }
  const double kf_ate = std::sqrt(sq / kf_aligned.size());
  const double odo_ate = odo.ate.rmse;
  CHECK(kf_ate < 0.15);
  CHECK(kf_ate <= odo_ate * 1.5);  // the window's final poses are no worse than the per-frame ones

  // Points and images.
  double share_sum = 0;
  std::size_t points = 0;
  for (const Keyframe& kf : keyframes) {
    INFO("keyframe at t = " << kf.t_ns);
    REQUIRE(!kf.image.empty());
    CHECK(kf.image.type() == CV_8UC1);
    REQUIRE(!kf.points.empty());
    int with_p_w = 0;
    for (const KeyframePoint& p : kf.points) {
      CHECK(p.weight >= 0.f);
      CHECK(p.weight <= 1.f);
      with_p_w += p.has_p_w ? 1 : 0;
    }
    share_sum += static_cast<double>(with_p_w) / kf.points.size();
    points += kf.points.size();
  }
  const double share = share_sum / keyframes.size();
  CHECK(share > 0.6);
  WARN("frames " << estimates.size() << ", kept " << kept.size() << ", dropped " << dropped.size() << ", keyframes out "
                 << keyframes.size() << " (" << points / keyframes.size() << " points each, " << share * 100
                 << " % with p_w); keyframe ATE " << kf_ate << " m (worst " << worst << " m), per-frame odometry ATE "
                 << odo_ate << " m");
}
