// The shipped chain on real data: VINS-Fusion's own EuRoC stereo-inertial config, unchanged, on the EuRoC
// V1_01 clip in ../shared, where the sensor stands still. It must initialise from standstill and stay put.
// run_vio_sequential: the stages of `dynavins run`, one after the other, iteration-bound (rate 0).
#include "tests/estimator/catch_with_ceres.hpp"

#include <filesystem>
#include <fstream>
#include <string>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "tests/log_capture.hpp"

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

namespace {
/// A copy of `clip` (symlinks but for the image lists) whose camera clock runs `lag_ns` behind the IMU's:
/// every image timestamp in cam0/cam1 data.csv is `lag_ns` earlier, the images and the rest unchanged.
std::string clip_with_camera_lag(const std::string& clip, int64_t lag_ns, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  fs::remove_all(out);
  const fs::path src = fs::path(clip) / "mav0", dst = out / "mav0";
  fs::create_directories(dst);
  for (const auto& e : fs::directory_iterator(src)) {
    const std::string name = e.path().filename().string();
    if (name != "cam0" && name != "cam1") {
      fs::create_symlink(e.path(), dst / name);
      continue;
    }
    fs::create_directories(dst / name);
    fs::create_symlink(e.path() / "data", dst / name / "data");
    std::ifstream in(e.path() / "data.csv");
    std::ofstream csv(dst / name / "data.csv");
    for (std::string line; std::getline(in, line);) {
      const auto comma = line.find(',');
      if (line.empty() || line[0] == '#' || comma == std::string::npos) {
        csv << line << "\n";
        continue;
      }
      csv << std::stoll(line.substr(0, comma)) - lag_ns << line.substr(comma) << "\n";
    }
  }
  return out.string();
}
}  // namespace

TEST_CASE("a camera clock behind the IMU's: the config's td puts the frames back in the IMU's clock",
          "[vio][euroc][td]") {
  // VINS-Fusion's convention: image clock + td = IMU clock. The same clip with every image stamped 3.7 ms
  // early (not a whole number of 5 ms IMU periods) and td = 0.0037 must give the original run bit for bit,
  // at the original times; with td = 0 the frames would be paired with the wrong IMU samples.
  const std::string config = kShared + "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml";
  const std::string clip = kShared + "/data/euroc_v1_01_micro";
  constexpr int64_t kLagNs = 3'700'000;
  const std::string lagged =
      clip_with_camera_lag(clip, kLagNs, std::filesystem::temp_directory_path() / "dynavins_test_td_clip");
  auto run = [&](const std::string& dir, double td) {
    pipeline::VioRunOptions opt;
    opt.estimator = EstimatorOptions::load(config);
    opt.estimator.td = td;
    opt.show_progress = false;
    io::EurocSource src(std::make_shared<io::EurocDataset>(dir));
    pipeline::EstimateRecorder r;
    pipeline::VioSinks sinks;
    sinks.estimate = [&r](const estimator::WindowEstimate& e) { r.record(e); };
    REQUIRE(pipeline::run_vio_sequential(src, opt, sinks).report.ok);
    return r;
  };
  const pipeline::EstimateRecorder original = run(clip, 0.0);
  const pipeline::EstimateRecorder with_td = run(lagged, 1e-9 * kLagNs);
  test::LogCapture log;
  const pipeline::EstimateRecorder without_td = run(lagged, 0.0);
  // Its first frame comes before the first IMU sample, so no interval starts there; the one-thread run
  // must not wait for a verdict on the frame after it (it did: 60 s, then on without it).
  CHECK_THAT(log.text.str(), Catch::Contains("no IMU at or before frame"));
  CHECK(log.text.str().find("no verdict") == std::string::npos);
  REQUIRE(original.estimate.poses.size() > 50);
  REQUIRE(with_td.estimate.poses.size() == original.estimate.poses.size());
  for (std::size_t i = 0; i < original.estimate.poses.size(); ++i) {
    INFO("pose " << i);
    CHECK(with_td.estimate.poses[i].t_ns == original.estimate.poses[i].t_ns);
    CHECK(with_td.estimate.poses[i].p == original.estimate.poses[i].p);
    CHECK(with_td.estimate.poses[i].q.coeffs() == original.estimate.poses[i].q.coeffs());
  }
  // Without td the run stays in the camera's clock (and pairs each frame with IMU 3.7 ms too early).
  REQUIRE_FALSE(without_td.estimate.poses.empty());
  const auto in_original = [&](int64_t t_ns) {
    for (const auto& p : original.estimate.poses)
      if (p.t_ns == t_ns) return true;
    return false;
  };
  CHECK(in_original(without_td.estimate.poses.back().t_ns + kLagNs));
  CHECK_FALSE(in_original(without_td.estimate.poses.back().t_ns));
  std::filesystem::remove_all(std::filesystem::path(lagged));
}
