// The shipped chain on real data: VINS-Fusion's own EuRoC stereo-inertial config, unchanged, on the EuRoC
// V1_01 clip in ../shared, where the sensor stands still. It must initialise from standstill and stay put.
// run_vio_sequential: the stages of `dynavins run`, one after the other, iteration-bound (rate 0).
#include "tests/estimator/catch_with_ceres.hpp"

#include <filesystem>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"

using namespace dynavins;

namespace {
const std::string kShared = DYNAVINS_SHARED_DIR;

double max_distance_from_start(const eval::Trajectory& t) {
  double d = 0;
  for (const auto& p : t.poses) d = std::max(d, (p.p - t.poses.front().p).norm());
  return d;
}
}  // namespace

TEST_CASE("EuRoC clip with VINS-Fusion's stereo-imu config: initialises at standstill and stays within 5 cm",
          "[vio][euroc]") {
  const std::string config = kShared + "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml";
  const std::string clip = kShared + "/data/euroc_v1_01_micro";
  REQUIRE(std::filesystem::is_regular_file(config));
  pipeline::VioRunOptions opt;
  opt.estimator = EstimatorOptions::load(config);
  opt.show_progress = false;
  for (auto loss : {estimator::BaLoss::Huber, estimator::BaLoss::Dynavins}) {
    INFO("BA " << estimator::to_string(loss));
    io::EurocSource src(std::make_shared<io::EurocDataset>(clip));
    opt.mode.loss = loss;
    pipeline::EstimateRecorder r;
    pipeline::VioSinks sinks;
    sinks.estimate = [&r](const estimator::WindowEstimate& e) { r.record(e); };
    const pipeline::VioRunResult run = pipeline::run_vio_sequential(src, opt, sinks);
    REQUIRE(run.report.ok);
    CHECK_FALSE(run.solver_time_budget);
    CHECK(r.resets == 0);
    // 11 frames fill the window; every frame after that is tracked.
    CHECK(r.tracking_frames >= r.frames - opt.estimator.window_size - 1);
    REQUIRE(r.tracking_frames > 50);
    CHECK(max_distance_from_start(r.estimate) < 0.05);
    // The sensor never moves: after the first tracked frame, the standstill detector finds it at rest.
    CHECK(r.standstill_t_ns.size() >= 0.9 * (r.tracking_frames - 1));
  }
}
