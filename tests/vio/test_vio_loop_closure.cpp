// Loop closure end to end (issue 21): a short E-shaped walk (tests/data/scenarios/e_shape_short.yaml, 24 s)
// through the shipped chain with `--loop dynavins` (run_vio_sequential, rate 0: the same answer on any
// machine). A parked truck is seen at the end of the first prong, moved 8 m while the camera faces away,
// and seen again at the end of the second prong: a persistent false loop whose view is the same. The walk
// back down the first prong revisits true places.
// What it checks, against the simulator's ground truth (a loop is true when its T_m^k is within 0.3 m and
// 5 deg of the truth's, as in loops.csv):
//   - the scene does produce both kinds of verified loops (else the test would prove nothing);
//   - the selective optimisation (paper IV, eq. 16-17) uses no false loop and adopts true ones;
//   - the loop-corrected trajectory stays close to the odometry, while the same verified loops with
//     `--loop all` (VINS-Fusion's handling, solved here on the run's own keyframes and loops) bend it by
//     metres: the false loops are real and harmful, and dynavins is what rejects them.
// The odometry of this scene is already at about 1 cm; the true loops' own T_m^k carry 0.3-3.4 cm of
// error, so adopting them may cost up to that much (measured when written: odometry 0.010 m, dynavins
// 0.018 m, 0.017 m since the two-way refinement of T_m^k; `all` 2.4 m; README, "Loop closure"). The bound
// below allows that and nothing near the `all` failure. Since skip_insignificant_correction (372fcc9) the
// loops are adopted but their correction, insignificant against the odometry here, is not applied: 0.010 m.
#include <algorithm>
#include <filesystem>
#include <map>

#include "tests/estimator/catch_with_ceres.hpp"

#include "eval/evaluation.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/loop_outputs.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"
#include "stages/loop/graph/loop_graph_optimizer.hpp"

using namespace dynavins;

namespace {

// A loop correction may move the path by about its true loops' own error (file comment), never by the
// metres a false loop costs.
constexpr double kMaxCostOverOdometryM = 0.05;
constexpr double kAllWorseFactor = 10.0;  // `all` on the same loops: at least this x dynavins' ATE

eval::Trajectory keyframe_trajectory(const std::map<int64_t, loop::RigidPose>& poses) {
  eval::Trajectory t;
  for (const auto& [t_ns, T] : poses) t.poses.push_back(eval::stamped_pose(t_ns, T.p, T.q));
  return t;
}

}  // namespace

TEST_CASE("loop closure end to end: the moved truck's false loops are rejected, true revisits adopted",
          "[vio][loop]") {
  const auto sc = sim::build_scenario(
      sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) + "/tests/data/scenarios/e_shape_short.yaml"));
  sim::ScenarioSource src(sc);
  pipeline::VioRunOptions opt;
  opt.estimator = sim::scenario_estimator_options(*sc);
  opt.mode.loss = estimator::BaLoss::Dynavins;
  opt.show_progress = false;
  opt.loop_mode = loop::LoopMode::Dynavins;
  opt.vocabulary = std::string(DYNAVINS_SOURCE_DIR) + "/data/vocabulary/default_vocabulary.bin";

  pipeline::EstimateRecorder rec;
  std::map<int64_t, loop::RigidPose> keyframes;  // odometry pose of every keyframe the loop closer got
  pipeline::VioSinks sinks;
  sinks.estimate = [&rec](const estimator::WindowEstimate& e) { rec.record(e); };
  sinks.keyframe = [&keyframes](const Keyframe& k) { keyframes[k.t_ns] = loop::RigidPose{k.p_wb, k.q_wb}; };
  const pipeline::VioRunResult r = pipeline::run_vio_sequential(src, opt, sinks);
  REQUIRE(r.report.ok);
  REQUIRE(r.resets == 0);
  REQUIRE(r.loop.has_value());
  const pipeline::LoopRunSummary& lp = *r.loop;
  REQUIRE(lp.keyframes == static_cast<int64_t>(keyframes.size()));

  const eval::Trajectory truth = pipeline::ground_truth_trajectory(r.ground_truth);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "dynavins_test_vio_loop_closure";
  std::filesystem::create_directories(dir);
  const pipeline::LoopTruthCounts c = pipeline::write_loops_csv((dir / "loops.csv").string(), lp, truth);
  std::filesystem::remove_all(dir);
  INFO("verified loops: " << c.true_loops << " true, " << c.false_loops << " false; adopted (weight >= 0.5): "
                          << c.true_adopted << " true, " << c.false_adopted << " false; used: " << c.true_used
                          << " true, " << c.false_used << " false; correction applied: " << lp.correction_applied);
  // The scene must produce what the test is about.
  REQUIRE(c.false_loops >= 3);
  REQUIRE(c.true_loops >= 3);
  CHECK(c.false_adopted == 0);
  CHECK(c.false_used == 0);
  CHECK(c.true_adopted >= 3);

  const double ate_odometry = eval::evaluate(truth, rec.estimate).ate.rmse;
  const double ate_dynavins = eval::evaluate(truth, pipeline::corrected_trajectory(rec.estimate, &lp)).ate.rmse;

  // The same keyframes and verified loops, every loop used with a Huber loss (LoopMode::All).
  loop::LoopGraphOptimizer all;
  for (const auto& [t_ns, T] : keyframes) all.add_keyframe(t_ns, T);
  for (const VerifiedLoop& l : lp.loops) REQUIRE(all.add_loop(l));
  const loop::LoopGraphResult res_all = all.optimize(loop::LoopMode::All);
  std::map<int64_t, loop::RigidPose> corrected_all;
  std::size_t i = 0;
  for (const auto& kv : keyframes) corrected_all[kv.first] = res_all.poses.at(i++);
  const double ate_all = eval::evaluate(truth, keyframe_trajectory(corrected_all)).ate.rmse;

  INFO("ATE odometry " << ate_odometry << " m, --loop dynavins " << ate_dynavins << " m, --loop all (keyframes) "
                       << ate_all << " m");
  CHECK(ate_dynavins <= ate_odometry + kMaxCostOverOdometryM);
  CHECK(ate_all >= kAllWorseFactor * ate_dynavins);
}
