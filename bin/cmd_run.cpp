// `dynavins run --config FILE.yaml (--euroc DIR | --log FILE | --rosbag FILE) [--rate R] [--out DIR]
//  [--ba huber|dynavins] [--mono] [--gyro-prediction] [--set key=value ...] [--lcm-url URL [--channel key=NAME]]`:
// the whole visual-inertial pipeline on a recording; writes odometry, weighted features, events and
// summary.json into --out, and with --lcm-url publishes while it runs (watch it in lcm-spy at --rate 1).
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "bin/sensor_input.hpp"
#include "bin/vio_command.hpp"
#include "pipeline/interrupt.hpp"
#include "stages/estimator/ba_mode.hpp"

namespace dynavins::cli {
namespace {
namespace fs = std::filesystem;

struct RunCommandOptions {
  VioCommandOptions vio;
  SensorInput input;
  double rate = 0.0;
};

std::string input_name(const SensorInput& in) {
  const std::string p = !in.euroc.empty() ? in.euroc : !in.rosbag.empty() ? in.rosbag : in.log;
  fs::path path(p);
  if (path.filename().empty()) path = path.parent_path();  // "dir/" -> "dir"
  return path.stem().string();
}

std::string input_label(const SensorInput& in) {
  if (!in.euroc.empty()) return "euroc:" + in.euroc;
  if (!in.rosbag.empty()) return "rosbag:" + in.rosbag;
  return "log:" + in.log;
}

void run(const RunCommandOptions& o) {
  if (!(o.rate >= 0.0)) throw CommandError("--rate must be >= 0 (0 = as fast as possible), got " + std::to_string(o.rate), 2);
  const pipeline::VioRunOptions opt = o.vio.load(o.rate);
  spdlog::info("{}", opt.estimator.print());

  pipeline::RunDescription what;
  what.config_path = o.vio.config;
  what.input = input_label(o.input);
  what.ba_loss = estimator::to_string(opt.mode.loss);
  what.stereo = opt.mode.stereo;
  what.rate = o.rate;
  const std::string out_dir = o.vio.out.empty() ? "runs/" + input_name(o.input) + "-" + what.ba_loss : o.vio.out;
  spdlog::info("run: {} BA, {}, rate {}, gyro-predicted KLT {} -> {}", what.ba_loss, what.stereo ? "stereo" : "mono",
               o.rate > 0 ? fmt::format("{}x real time", o.rate) : std::string("as fast as possible"),
               opt.gyro_prediction ? "on" : "off", out_dir);

  auto source = o.input.open(/*need_stereo=*/opt.mode.stereo);
  run_vio_with_outputs(*source, opt, what, out_dir, InterruptIs::Failure);
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto o = std::make_shared<RunCommandOptions>();
  auto* cmd = app.add_subcommand("run", "Run the visual-inertial estimator on a recording; write odometry and a summary");
  o->input.add_options(*cmd, /*with_log=*/true);
  cmd->add_option("--rate", o->rate, "x real time; 0 = as fast as possible (blocking, lossless)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  o->vio.add_options(*cmd,
                     "Publish poses, weighted features, status and stats on LCM while running, e.g. "
                     "udpm://239.255.76.67:7667?ttl=0 (default: publish nothing)");
  cmd->callback([o] {
    pipeline::install_interrupt_handler();
    run(*o);
  });
}

}  // namespace dynavins::cli
