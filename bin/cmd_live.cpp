// `dynavins live --config FILE.yaml --lcm-url URL [--out DIR] [--input key=NAME ...] [run options]`: the
// pipeline on live sensors. Subscribes to the stereo-image and IMU channels (and ground truth, when a
// simulator or a log player sends it), runs in real time (frames the tracker cannot keep up with are
// dropped oldest first and counted; IMU is never dropped), publishes its outputs on the same LCM URL
// (or --publish-url), and on SIGINT drains every queue and writes the same outputs as `run`.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "bin/vio_command.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/lcm_live_source.hpp"
#include "stages/estimator/ba_mode.hpp"

namespace dynavins::cli {
namespace {

struct LiveCommandOptions {
  VioCommandOptions vio;
  std::string publish_url;          ///< default: vio.lcm_url
  std::vector<std::string> inputs;  ///< input channel overrides, key=NAME
};

void set_input_channel(pipeline::LiveSourceOptions& s, const std::string& assignment) {
  const auto eq = assignment.find('=');
  const std::string key = assignment.substr(0, eq), name = eq == std::string::npos ? "" : assignment.substr(eq + 1);
  if (eq == std::string::npos) throw CommandError("--input '" + assignment + "': expected key=NAME (keys: stereo, imu, ground_truth)", 2);
  if (key == "stereo" && !name.empty()) s.stereo_channel = name;
  else if (key == "imu" && !name.empty()) s.imu_channel = name;
  else if (key == "ground_truth") s.ground_truth_channel = name;  // empty: do not read ground truth
  else throw CommandError("--input '" + assignment + "': unknown key or empty name (keys: stereo, imu, ground_truth)", 2);
}

void live(const LiveCommandOptions& o) {
  VioCommandOptions vio = o.vio;
  const std::string input_url = vio.lcm_url;
  if (!o.publish_url.empty()) vio.lcm_url = o.publish_url;
  pipeline::VioRunOptions opt = vio.load(0.0);
  opt.live = true;
  opt.show_progress = false;
  spdlog::info("{}", opt.estimator.print());

  pipeline::LiveSourceOptions in;
  in.url = input_url;
  in.image_width = opt.estimator.cameras.at(0)->width();
  in.image_height = opt.estimator.cameras.at(0)->height();
  for (const std::string& a : o.inputs) set_input_channel(in, a);

  pipeline::RunDescription what;
  what.config_path = vio.config;
  what.input = "live:" + input_url;
  what.ba_loss = estimator::to_string(opt.mode.loss);
  what.stereo = opt.mode.stereo;
  const std::string out_dir = vio.out.empty() ? "runs/live-" + what.ba_loss : vio.out;

  std::unique_ptr<pipeline::LcmLiveSource> source;
  try {
    source = std::make_unique<pipeline::LcmLiveSource>(in);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }
  spdlog::info("live: listening on {} ({}, {}), publishing on {}; Ctrl-C ends the run and writes {}", input_url,
               in.stereo_channel, in.imu_channel, opt.lcm_url, out_dir);
  run_vio_with_outputs(*source, opt, what, out_dir, InterruptIs::NormalEnd, [&] {
    const auto& s = source->stats();
    std::printf("live input  %lld frames, %lld IMU samples, %lld ground-truth states; rejected: %lld of another type, "
                "%lld undecodable, %lld bad images, %lld bad IMU, %lld going back in time\n",
                static_cast<long long>(s.frames), static_cast<long long>(s.imu), static_cast<long long>(s.ground_truth),
                static_cast<long long>(s.wrong_type), static_cast<long long>(s.undecodable),
                static_cast<long long>(s.bad_image), static_cast<long long>(s.bad_imu),
                static_cast<long long>(s.time_went_back));
  });
}

}  // namespace

void add_live_command(CLI::App& app) {
  auto o = std::make_shared<LiveCommandOptions>();
  auto* cmd = app.add_subcommand("live", "Run on live LCM sensor channels until Ctrl-C; publish and write outputs");
  o->vio.add_options(*cmd, "LCM URL to subscribe (and publish) on, e.g. udpm://239.255.76.67:7667?ttl=0");
  cmd->get_option("--lcm-url")->required();
  cmd->add_option("--publish-url", o->publish_url, "Publish on this LCM URL instead of --lcm-url");
  cmd->add_option("--input", o->inputs,
                  "Rename an input channel: --input key=NAME (keys: stereo [CAM_STEREO], imu [IMU], ground_truth "
                  "[GROUND_TRUTH; empty = ignore])");
  cmd->callback([o] {
    pipeline::install_interrupt_handler();
    live(*o);
  });
}

}  // namespace dynavins::cli
