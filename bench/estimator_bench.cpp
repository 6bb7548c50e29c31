// bench_estimator: one scenario, huber and dynavins side by side through the deterministic sequential
// chain (tracker -> IMU -> estimator on one thread): ATE, feature scoring, BA ms.
//   bench_estimator --scenario high [--duration S] [--mono] [--ba huber,dynavins]
#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <iostream>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bench/sequential_vio.hpp"
#include "eval/evaluation.hpp"
#include "eval/trajectory_io.hpp"
#include "sim/scenario/scenario.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins;

int main(int argc, char** argv) {
  CLI::App app{"Huber vs DynaVINS on one simulated scenario (sequential, deterministic)"};
  std::string scenario = "high", modes = "huber,dynavins", level = "warn";
  std::optional<double> duration;
  bool mono = false;
  std::string out_dir;
  app.add_option("--scenario", scenario, "Name in bench/scenarios or a file")->capture_default_str();
  app.add_option("--duration", duration, "Seconds to simulate (default: the scenario's)");
  app.add_option("--ba", modes, "Comma-separated BA losses")->capture_default_str();
  app.add_flag("--mono", mono, "Mono-inertial (cam0 only)");
  app.add_option("--log-level", level)->capture_default_str();
  app.add_option("--out", out_dir, "Write <ba>.tum and groundtruth.tum here");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(level));

  std::string path = scenario;
  if (!std::filesystem::is_regular_file(path)) path = std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/" + scenario + ".yaml";
  const auto sc = sim::build_scenario(sim::load_scenario(path), std::nullopt, duration);
  const auto dir = std::filesystem::temp_directory_path() / ("bench_estimator_" + std::to_string(::getpid()));
  io::write_vins_stereo_config(dir.string(), sim::vins_config(*sc));
  const EstimatorOptions opt = EstimatorOptions::load((dir / "vins_config.yaml").string());
  std::filesystem::remove_all(dir);

  std::stringstream ss(modes);
  std::string m;
  while (std::getline(ss, m, ',')) {
    estimator::EstimatorMode mode;
    mode.loss = estimator::parseBaLoss(m);
    mode.stereo = !mono;
    sim::ScenarioSource src(sc);
    const auto r = bench::runSequentialVio(src, opt, mode);
    if (!out_dir.empty()) {
      std::filesystem::create_directories(out_dir);
      eval::write_tum(out_dir + "/" + m + ".tum", r.estimate);
      eval::write_tum(out_dir + "/groundtruth.tum", r.ground_truth);
    }
    double ate = -1;
    try {
      ate = eval::evaluate(r.ground_truth, r.estimate).ate.rmse;
    } catch (const std::exception& e) {
      spdlog::warn("{}: no ATE: {}", m, e.what());
    }
    std::vector<double> ba = r.ba_ms;
    std::sort(ba.begin(), ba.end());
    double mean = 0;
    for (double v : ba) mean += v;
    mean = ba.empty() ? 0 : mean / ba.size();
    const double p95 = ba.empty() ? 0 : ba[static_cast<size_t>(0.95 * (ba.size() - 1))];
    const auto sw = bench::scoreWeights(r.features);
    std::printf("%-9s %s %s: ATE %.4f m | frames %d tracking %d resets %d | BA ms mean %.2f p95 %.2f | "
                "moving %d rejected %.1f%% | static %d kept %.1f%%\n",
                m.c_str(), scenario.c_str(), mono ? "mono" : "stereo", ate, r.frames, r.tracking_frames, r.resets,
                mean, p95, sw.moving, 100 * sw.moving_rejected, sw.static_, 100 * sw.static_kept);
    std::fflush(stdout);
  }
  return 0;
}
