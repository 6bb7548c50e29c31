// Estimator faults (issue 22), injected into a short static street (tests/data/scenarios/
// street_static_short.yaml, 12 s at 3 m/s) on its way to the shipped chain (run_vio_sequential, rate 0):
// both cameras go black for 2 s, then a burst of frames never arrives, then the IMU biases jump. What a
// robot needs from the estimate through all this: no NaN, no silent jump of the pose (a discontinuity is
// only allowed where a reset is reported, with its reason), and tracking again once the images are back.
#include <string>
#include <vector>

#include "tests/estimator/catch_with_ceres.hpp"
#include "tests/vio/fault_injection_source.hpp"

#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins;

namespace {

constexpr int64_t kSec = 1'000'000'000;

bool finite(const NavState& s) {
  return s.p_wb.allFinite() && s.q_wb.coeffs().allFinite() && s.v_wb.allFinite() && s.bias_gyr.allFinite() &&
         s.bias_acc.allFinite();
}

}  // namespace

TEST_CASE("black images, dropped frames and a bias jump: reported, never NaN, no silent jump, recovered",
          "[vio][faults]") {
  const auto sc = sim::build_scenario(sim::load_scenario(std::string(DYNAVINS_SOURCE_DIR) +
                                                         "/tests/data/scenarios/street_static_short.yaml"));
  sim::ScenarioSource scene(sc);
  test::FaultPlan plan;
  plan.black_from_ns = 3 * kSec + kSec / 2, plan.black_to_ns = 5 * kSec + kSec / 2;
  plan.drop_from_ns = 7 * kSec, plan.drop_to_ns = 7 * kSec + 6 * kSec / 10;
  plan.bias_jump_ns = 9 * kSec;
  plan.acc_jump = Eigen::Vector3d(0.2, -0.1, 0.1);  // several times a consumer IMU's turn-on bias spread
  plan.gyr_jump = Eigen::Vector3d(0.0, 0.005, -0.01);
  test::FaultInjectionSource src(scene, plan);

  pipeline::VioRunOptions opt;
  opt.estimator = sim::scenario_estimator_options(*sc);
  opt.show_progress = false;
  std::vector<estimator::WindowEstimate> estimates;
  pipeline::VioSinks sinks;
  sinks.estimate = [&estimates](const estimator::WindowEstimate& e) {
    estimator::WindowEstimate kept;  // the state and status only: the features are not needed here
    kept.t_ns = e.t_ns, kept.status = e.status, kept.state = e.state, kept.event = e.event;
    estimates.push_back(std::move(kept));
  };
  const pipeline::VioRunResult r = pipeline::run_vio_sequential(src, opt, sinks);
  REQUIRE(r.report.ok);
  REQUIRE(src.frames_black > 20);
  REQUIRE(src.frames_dropped > 5);
  const std::map<int64_t, double> speed = pipeline::ground_truth_speed(r.ground_truth);
  REQUIRE(!speed.empty());

  int resets = 0;
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    const estimator::WindowEstimate& e = estimates[k];
    INFO("t = " << (e.t_ns - src.start_ns()) * 1e-9 << " s, event '" << e.event << "'");
    if (e.status == estimator::EstimatorStatus::Reset) {
      ++resets;
      CHECK(e.event.rfind("reset: ", 0) == 0);
      CHECK(e.event.size() > 10);  // a reason follows
    }
    if (e.status != estimator::EstimatorStatus::Tracking) continue;
    CHECK(finite(e.state));
    // No silent jump: between two consecutive tracking estimates the pose moves no more than the true
    // motion over that time allows (speed ~3 m/s; 0.5 m of slack is several frames' travel).
    if (k == 0 || estimates[k - 1].status != estimator::EstimatorStatus::Tracking) continue;
    const estimator::WindowEstimate& prev = estimates[k - 1];
    const double dt = (e.t_ns - prev.t_ns) * 1e-9;
    const auto it = speed.lower_bound(e.t_ns);
    REQUIRE(it != speed.end());
    const double step = (e.state.p_wb - prev.state.p_wb).norm();
    if (getenv("DBG")) printf("t %.2f step %.3f v %.2f %.2f %.2f ba %.3f %.3f %.3f\n", (e.t_ns - src.start_ns())*1e-9, step, e.state.v_wb.x(), e.state.v_wb.y(), e.state.v_wb.z(), e.state.bias_acc.x(), e.state.bias_acc.y(), e.state.bias_acc.z());
    INFO("step " << step << " m over " << dt << " s at true speed " << it->second << " m/s");
    CHECK(step < 1.5 * it->second * dt + 0.5);
  }
  CHECK(resets == r.resets);

  // Recovered: in the last 2 s (2.9 s after the bias jump) the estimator tracks again.
  int late = 0, late_tracking = 0;
  for (const auto& e : estimates) {
    if (e.t_ns - src.start_ns() < 10 * kSec) continue;
    ++late;
    late_tracking += e.status == estimator::EstimatorStatus::Tracking;
  }
  INFO("resets " << resets << ", late frames " << late << ", tracking " << late_tracking);
  REQUIRE(late > 20);
  CHECK(late_tracking >= 0.9 * late);
  CHECK(estimates.back().status == estimator::EstimatorStatus::Tracking);
}
