// `dynavins run --config FILE.yaml (--euroc DIR | --log FILE | --rosbag FILE) [--rate R] [--out DIR]
//  [--ba huber|dynavins] [--mono] [--gyro-prediction] [--set key=value ...] [--lcm-url URL [--channel key=NAME]]`: the whole
// visual-inertial pipeline on a recording; writes odometry, weighted features, events and summary.json into --out.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "bin/sensor_input.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/report_format.hpp"
#include "pipeline/vio/run_outputs.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "stages/common/config_error.hpp"
#include "stages/estimator/ba_mode.hpp"

namespace dynavins::cli {
namespace {
namespace fs = std::filesystem;

struct RunCommandOptions {
  std::string config;
  SensorInput input;
  double rate = 0.0;
  std::string out;
  std::string ba = "dynavins";
  bool mono = false;
  std::vector<std::string> set;
  double imu_rate_hz = 200.0;
  bool gyro_prediction = false;
  std::string lcm_url;
  std::vector<std::string> channels;
};

std::string inputName(const SensorInput& in) {
  const std::string p = !in.euroc.empty() ? in.euroc : !in.rosbag.empty() ? in.rosbag : in.log;
  fs::path path(p);
  if (path.filename().empty()) path = path.parent_path();  // "dir/" -> "dir"
  return path.stem().string();
}

std::string inputLabel(const SensorInput& in) {
  if (!in.euroc.empty()) return "euroc:" + in.euroc;
  if (!in.rosbag.empty()) return "rosbag:" + in.rosbag;
  return "log:" + in.log;
}

void run(const RunCommandOptions& o) {
  if (!(o.rate >= 0.0)) throw CommandError("--rate must be >= 0 (0 = as fast as possible), got " + std::to_string(o.rate), 2);
  pipeline::VioRunOptions opt;
  try {
    std::vector<std::pair<std::string, std::string>> overrides;
    for (const std::string& s : o.set) overrides.push_back(EstimatorOptions::parseOverride(s));
    opt.estimator = EstimatorOptions::load(o.config, overrides);
    opt.mode.loss = estimator::parseBaLoss(o.ba);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }
  opt.mode.stereo = !o.mono;
  opt.rate = o.rate;
  opt.imu_rate_hz = o.imu_rate_hz;
  opt.gyro_prediction = o.gyro_prediction;
  opt.lcm_url = o.lcm_url;
  try {
    for (const std::string& c : o.channels) opt.channels.set(c);
    pipeline::checkVioOptions(opt);
  } catch (const std::invalid_argument& e) {
    throw CommandError(e.what(), 2);
  }
  spdlog::info("{}", opt.estimator.print());

  pipeline::RunDescription what;
  what.config_path = o.config;
  what.input = inputLabel(o.input);
  what.ba_loss = estimator::toString(opt.mode.loss);
  what.stereo = opt.mode.stereo;
  what.rate = o.rate;
  const std::string out_dir = o.out.empty() ? "runs/" + inputName(o.input) + "-" + what.ba_loss : o.out;
  spdlog::info("run: {} BA, {}, rate {}, gyro-predicted KLT {} -> {}", what.ba_loss, what.stereo ? "stereo" : "mono",
               o.rate > 0 ? fmt::format("{}x real time", o.rate) : std::string("as fast as possible"),
               opt.gyro_prediction ? "on" : "off", out_dir);

  auto source = o.input.open(/*need_stereo=*/opt.mode.stereo);
  std::unique_ptr<pipeline::RunOutputs> outputs;
  try {
    outputs = std::make_unique<pipeline::RunOutputs>(out_dir);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }
  pipeline::VioSinks sinks;
  sinks.estimate = [&](const estimator::WindowEstimate& e) { outputs->write(e); };
  pipeline::VioRunResult r;
  try {
    r = pipeline::runVio(*source, opt, sinks);
  } catch (const std::exception& e) {  // options that cannot run, an LCM URL that does not open
    throw CommandError(e.what(), 2);
  }
  if (!r.report.ok) {
    std::fprintf(stderr, "%s", pipeline::format_report(r.report).c_str());
    throw CommandError("run failed in thread '" + r.report.failed_thread + "': " + r.report.error +
                           " (outputs left as .partial in " + out_dir + ")",
                       1);
  }
  outputs->complete(r, what);

  const auto& t = outputs->totals();
  std::printf("%s", pipeline::format_report(r.report).c_str());
  std::printf("frames      %lld in, %lld tracked, %lld dropped, %lld estimated, %lld tracking (%.1f %%)%s\n",
              static_cast<long long>(r.replay.frames), static_cast<long long>(r.frames_tracked),
              static_cast<long long>(r.frames_dropped), static_cast<long long>(t.estimates),
              static_cast<long long>(t.tracking), t.estimates ? 100.0 * t.tracking / t.estimates : 0.0,
              r.interrupted() ? "  (interrupted)" : "");
  if (r.gyro_prediction)
    std::printf("gyro KLT    %lld frames predicted, %lld not (first, after a drop or an IMU gap); %lld KLT from the "
                "prediction, %lld tracks carried over\n",
                static_cast<long long>(r.frames_gyro_predicted), static_cast<long long>(r.frames_gyro_unpredicted),
                static_cast<long long>(r.features_gyro_predicted), static_cast<long long>(r.features_tracked));
  if (!t.ba_ms.empty()) {
    double sum = 0, mx = 0;
    for (double x : t.ba_ms) sum += x, mx = std::max(mx, x);
    std::printf("BA          %zu solves, %.2f ms mean, %.2f ms max\n", t.ba_ms.size(), sum / t.ba_ms.size(), mx);
  } else {
    std::printf("BA          no solves\n");
  }
  std::printf("time        %.2f s of data in %.2f s: %.2fx real time\n", r.replay.sensor_s, r.report.wall_s,
              r.report.wall_s > 0 ? r.replay.sensor_s / r.report.wall_s : 0.0);
  if (outputs->ate().evaluated)
    std::printf("ATE         %.4f m (SE3), %.4f m (Sim3) over %zu poses\n", outputs->ate().se3_m,
                outputs->ate().sim3_m, outputs->ate().matched);
  else if (!outputs->ate().error.empty())
    std::printf("ATE         not computed: %s\n", outputs->ate().error.c_str());
  if (r.publisher)
    std::printf("lcm         %s: %lld IMU-rate poses, %lld window poses, %lld feature sets, %lld dropped, %lld failed; "
                "IMU pose latency mean %.3f ms, p99 %.3f ms\n",
                r.publisher->url.c_str(), static_cast<long long>(r.publisher->imu_poses),
                static_cast<long long>(r.publisher->window_poses), static_cast<long long>(r.publisher->feature_sets),
                static_cast<long long>(r.publish_dropped), static_cast<long long>(r.publisher->failed),
                r.publisher->imu_pose_latency.mean_ms, r.publisher->imu_pose_latency_p99_ms);
  std::printf("outputs     %s\n", out_dir.c_str());
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCommandOptions>();
  auto* cmd = app.add_subcommand("run", "Run the visual-inertial estimator on a recording; write odometry and a summary");
  cmd->add_option("--config", o->config, "VINS-Fusion / DynaVINS yaml")->required()->check(CLI::ExistingFile);
  o->input.add_options(*cmd, /*with_log=*/true);
  cmd->add_option("--rate", o->rate, "x real time; 0 = as fast as possible (blocking, lossless)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--out", o->out, "Output directory (default runs/<input name>-<ba>)");
  cmd->add_option("--ba", o->ba, "Bundle-adjustment loss")
      ->check(CLI::IsMember({"huber", "dynavins"}))
      ->capture_default_str();
  cmd->add_flag("--mono", o->mono, "Use cam0 only");
  cmd->add_flag("--gyro-prediction", o->gyro_prediction,
                "Seed the tracker's KLT with the gyro-integrated rotation (bias from the estimator; the run then "
                "depends on thread timing and is not bit-repeatable)");
  cmd->add_option("--set", o->set, "Override a yaml option: --set key=value (repeatable)");
  cmd->add_option("--lcm-url", o->lcm_url,
                  "Publish poses, weighted features, status and stats on LCM while running, e.g. "
                  "udpm://239.255.76.67:7667?ttl=0 (default: publish nothing)");
  cmd->add_option("--channel", o->channels,
                  "Rename an output channel: --channel key=NAME (keys: pose_imu, pose, features, status, stats)");
  cmd->add_option("--imu-rate", o->imu_rate_hz, "Nominal IMU rate [Hz], for IMU gap detection")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
  cmd->callback([o] {
    pipeline::install_interrupt_handler();
    run(*o);
  });
}

}  // namespace dynavins::cli
