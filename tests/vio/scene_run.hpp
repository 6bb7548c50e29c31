#pragma once
// One simulated scene through the shipped chain (run_vio_sequential, rate 0: iteration-bound, so the same
// answer on any machine), scored against the simulator's ground truth. Shared by the scene tests.
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <memory>

#include "tests/estimator/catch_with_ceres.hpp"

#include "eval/evaluation.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario_config.hpp"

namespace dynavins::test {

struct SceneRun {
  pipeline::EstimateRecorder run;          ///< every estimate of the run
  std::map<int64_t, double> true_speed;    ///< ground-truth speed [m/s] by time [ns]
  double ate = 1e9;                        ///< ATE RMSE [m] (SE3) against the ground truth; NaN if undefined
};

/// `edit`, when given, changes the scenario's estimator options before the run (an A/B of one key).
inline SceneRun run_scene(const std::shared_ptr<const sim::Scenario>& sc, estimator::BaLoss loss, bool stereo = true,
                          const std::function<void(EstimatorOptions&)>& edit = {}) {
  sim::ScenarioSource src(sc);
  pipeline::VioRunOptions opt;
  opt.estimator = sim::scenario_estimator_options(*sc);
  if (edit) edit(opt.estimator);
  opt.mode.loss = loss;
  opt.mode.stereo = stereo;
  opt.show_progress = false;
  SceneRun o;
  pipeline::VioSinks sinks;
  sinks.estimate = [&o](const estimator::WindowEstimate& e) { o.run.record(e); };
  const pipeline::VioRunResult r = pipeline::run_vio_sequential(src, opt, sinks);
  REQUIRE(r.report.ok);
  o.true_speed = pipeline::ground_truth_speed(r.ground_truth);
  try {
    o.ate = eval::evaluate(pipeline::ground_truth_trajectory(r.ground_truth), o.run.estimate).ate.rmse;
  } catch (const std::exception&) {
    o.ate = std::numeric_limits<double>::quiet_NaN();  // a straight path has no SE3 alignment; NaN fails any bound
  }
  return o;
}

}  // namespace dynavins::test
