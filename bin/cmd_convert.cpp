// `dynavins convert (--euroc DIR | --rosbag FILE.bag) --out FILE.lcmlog`: a recorded data set as an LCM event log
// (stereo images, IMU, ground truth), the project's replayable sensor-log format. The log is
// written to FILE.lcmlog.partial and renamed only when complete: a failed conversion leaves no
// file that could pass for a whole log.
#include <filesystem>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "bin/sensor_input.hpp"
#include "pipeline/progress.hpp"
#include "pipeline/sensor_log.hpp"

namespace dynavins::cli {
namespace {

struct ConvertOptions {
  SensorInput input;
  std::string out;
  bool raw = false;
};

void run_convert(const ConvertOptions& o) {
  // Checked before anything is written: a conversion must not run for minutes and fail on the rename.
  namespace fs = std::filesystem;
  if (fs::is_directory(o.out)) throw CommandError("--out " + o.out + " is a directory; give the log file's name", 2);
  const fs::path parent = fs::path(o.out).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw CommandError("--out " + o.out + ": the folder " + parent.string() + " does not exist", 2);
  auto source = o.input.open();
  const std::string partial = o.out + ".partial";
  int64_t frames = 0, imu = 0, gt = 0;
  try {
    pipeline::LcmLogWriter log(partial);
    pipeline::Progress progress("convert");
    SensorEvent e;
    while (source->next(e)) {
      pipeline::write_sensor_event(log, e, o.raw ? pipeline::ImageEncoding::Gray8 : pipeline::ImageEncoding::Png);
      frames += std::holds_alternative<StereoFrame>(e);
      imu += std::holds_alternative<ImuSample>(e);
      gt += std::holds_alternative<GroundTruthState>(e);
      progress.update(source->progress(), fmt::format("{} frames", frames));
    }
    log.close();
    progress.done(fmt::format("{} stereo frames, {} IMU samples, {} ground-truth states", frames, imu, gt));
  } catch (const std::exception& e) {
    std::filesystem::remove(partial);
    throw CommandError(std::string(e.what()) + " (nothing written to " + o.out + ")", 2);
  }
  std::filesystem::rename(partial, o.out);
  spdlog::info("wrote {} from {}", o.out, source->describe());
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto o = std::make_shared<ConvertOptions>();
  auto* cmd = app.add_subcommand("convert", "Convert a recorded data set (EuRoC folder, ROS 1 bag) into an LCM sensor log");
  o->input.add_options(*cmd, /*with_log=*/false);
  cmd->add_option("--out", o->out, "Output LCM log")->required();
  cmd->add_flag("--raw", o->raw, "Store images as raw gray8 instead of PNG (larger, faster to read)");
  cmd->callback([o] { run_convert(*o); });
}

}  // namespace dynavins::cli
