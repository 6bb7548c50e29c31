#include "bin/vio_command.hpp"

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <memory>
#include <utility>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "pipeline/report_format.hpp"
#include "stages/estimator/ba_mode.hpp"
#include "stages/loop/graph/loop_mode.hpp"

namespace dynavins::cli {

void VioCommandOptions::add_options(CLI::App& cmd, const std::string& lcm_url_help) {
  cmd.add_option("--config", config, "VINS-Fusion / DynaVINS yaml")->required()->check(CLI::ExistingFile);
  cmd.add_option("--out", out, "Output directory (default runs/<input name>-<ba>)");
  cmd.add_option("--ba", ba, "Bundle-adjustment loss")->check(CLI::IsMember({"huber", "dynavins"}))->capture_default_str();
  cmd.add_flag("--mono", mono, "Use cam0 only");
  cmd.add_flag("--gyro-prediction", gyro_prediction,
               "Seed the tracker's KLT with the gyro-integrated rotation (bias from the estimator; the run then "
               "depends on thread timing and is not bit-repeatable)");
  cmd.add_option("--set", set, "Override a yaml option: --set key=value (repeatable)");
  cmd.add_option("--imu-rate", imu_rate_hz, "Nominal IMU rate [Hz], for IMU gap detection")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
  cmd.add_option("--lcm-url", lcm_url, lcm_url_help);
  cmd.add_option("--loop", loop,
                 "Loop closure: off (odometry only), all (every verified loop, Huber), switchable (switchable "
                 "constraints), dynavins (selective optimisation of grouped hypotheses, paper IV)")
      ->check(CLI::IsMember({"off", "all", "switchable", "dynavins"}))
      ->capture_default_str();
  cmd.add_option("--vocabulary", vocabulary, "Vocabulary tree for place recognition (default: the shipped one)");
  cmd.add_option("--rt-priority", realtime_priority,
                 "Real-time runs: SCHED_FIFO priority of the IMU and publisher threads when the process may (root, "
                 "CAP_SYS_NICE or an rtprio limit), so the IMU-rate pose is not held up on a busy machine; 0 = off")
      ->check(CLI::Range(0, 99))
      ->capture_default_str();
  cmd.add_option("--channel", channels,
                 "Rename an output channel: --channel key=NAME (keys: pose_imu, pose, pose_corrected, features, status, stats, "
                 "loops, path)");
}

pipeline::VioRunOptions VioCommandOptions::load(double rate) const {
  pipeline::VioRunOptions opt;
  try {
    std::vector<std::pair<std::string, std::string>> overrides;
    for (const std::string& s : set) overrides.push_back(EstimatorOptions::parse_override(s));
    opt.estimator = EstimatorOptions::load(config, overrides);
    opt.mode.loss = estimator::parse_ba_loss(ba);
    opt.mode.stereo = !mono;
    opt.rate = rate;
    opt.imu_rate_hz = imu_rate_hz;
    opt.gyro_prediction = gyro_prediction;
    opt.realtime_priority = realtime_priority;
    opt.lcm_url = lcm_url;
    for (const std::string& c : channels) opt.channels.set(c);
    opt.loop_mode = loop::parse_loop_mode(loop);
    if (opt.loop_mode != loop::LoopMode::Off) {
      opt.vocabulary = vocabulary.empty() ? default_vocabulary_path() : vocabulary;
      if (!std::filesystem::is_regular_file(opt.vocabulary))
        throw std::invalid_argument("--vocabulary " + opt.vocabulary + ": no such file (or --loop off)");
    }
    pipeline::check_vio_options(opt);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }
  return opt;
}

std::string default_vocabulary_path() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share/dynavins/default_vocabulary.bin";
    if (fs::is_regular_file(installed)) return installed.string();
  }
  return std::string(DYNAVINS_SOURCE_DIR) + "/data/vocabulary/default_vocabulary.bin";
}

namespace {

void print_summary(const pipeline::VioRunResult& r, const pipeline::RunOutputs& outputs, const std::string& out_dir) {
  const auto& t = outputs.totals();
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
  if (r.publisher)
    std::printf("lcm         %s: %lld IMU-rate poses, %lld window poses, %lld feature sets, %lld dropped, %lld failed; "
                "IMU pose latency mean %.3f ms, p99 %.3f ms\n",
                r.publisher->url.c_str(), static_cast<long long>(r.publisher->imu_poses),
                static_cast<long long>(r.publisher->window_poses), static_cast<long long>(r.publisher->feature_sets),
                static_cast<long long>(r.publish_dropped), static_cast<long long>(r.publisher->failed),
                r.publisher->imu_pose_latency.mean_ms, r.publisher->imu_pose_latency_p99_ms);
  if (r.loop)
    std::printf(
        "loop        %s: %lld keyframes, %zu verified loops, %lld optimisations, %.1f ms per keyframe "
        "(max %.1f; the loop thread's CPU %.1f)%s\n",
        loop::loop_mode_name(r.loop->mode), static_cast<long long>(r.loop->keyframes), r.loop->loops.size(),
        static_cast<long long>(r.loop->optimizations), r.loop->keyframe_ms_mean, r.loop->keyframe_ms_max,
        r.loop->keyframe_cpu_ms_mean,
        r.loop->keyframes_dropped ? fmt::format(", {} keyframes dropped", r.loop->keyframes_dropped).c_str() : "");
  if (outputs.ate().evaluated)
    std::printf("ATE         %.4f m (SE3), %.4f m (Sim3) over %zu poses (odometry)\n", outputs.ate().se3_m,
                outputs.ate().sim3_m, outputs.ate().matched);
  if (r.loop && outputs.trajectory_ate().evaluated)
    std::printf("ATE         %.4f m (SE3), %.4f m (Sim3) after loop closure (trajectory.tum)\n",
                outputs.trajectory_ate().se3_m, outputs.trajectory_ate().sim3_m);
  else if (!outputs.ate().error.empty())
    std::printf("ATE         not computed: %s\n", outputs.ate().error.c_str());
  std::printf("outputs     %s\n", out_dir.c_str());
}

}  // namespace

void run_vio_with_outputs(io::SensorSource& source, const pipeline::VioRunOptions& opt,
                          const pipeline::RunDescription& what, const std::string& out_dir,
                          InterruptIs interrupt, const std::function<void()>& extra_summary) {
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
    r = pipeline::run_vio(source, opt, sinks);
  } catch (const std::exception& e) {  // options that cannot run, an LCM URL that does not open
    throw CommandError(e.what(), 2);
  }
  if (!r.report.ok) {
    std::fprintf(stderr, "%s", pipeline::format_report(r.report).c_str());
    throw CommandError("run failed in thread '" + r.report.failed_thread + "': " + r.report.error +
                           " (outputs left as .partial in " + out_dir + ")",
                       1);
  }
  // A run that produced no pose did not succeed, whatever its threads say: an empty log, IMU that never
  // overlaps the images, a scene the estimator never initialised on.
  const bool no_pose = r.frames_tracking == 0;
  if (no_pose) {
    r.report.ok = false;
    r.report.error = "no pose was estimated (" + std::to_string(r.replay.frames) + " frames in, " +
                     std::to_string(r.frames_estimated) + " estimated, none tracking)";
  }
  outputs->complete(r, what);
  print_summary(r, *outputs, out_dir);
  if (extra_summary) extra_summary();
  if (no_pose) throw CommandError(r.report.error + "; summary in " + out_dir + "/summary.json says ok: false", 1);
  if (r.interrupted() && interrupt == InterruptIs::Failure)
    throw CommandError(fmt::format("interrupted: the outputs in {} cover {:.1f} s of data only (summary.json says "
                                   "interrupted: true)",
                                   out_dir, r.replay.sensor_s),
                       130);
}

}  // namespace dynavins::cli
