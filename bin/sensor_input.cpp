#include "bin/sensor_input.hpp"

#include <CLI/CLI.hpp>

#include "bin/commands.hpp"
#include "io/euroc_source.hpp"
#include "io/rosbag/rosbag_reader.hpp"
#include "pipeline/sensor_log.hpp"

namespace dynavins::cli {

void SensorInput::add_options(CLI::App& cmd, bool with_log) {
  auto* group = cmd.add_option_group("input", "recorded sensor data (exactly one)");
  group->add_option("--euroc", euroc, "EuRoC ASL folder (holding mav0/)")->check(CLI::ExistingDirectory);
  group->add_option("--rosbag", rosbag, "ROS 1 bag with VIODE's topics (/cam0/image_raw, /cam1/image_raw, /imu0, /odometry)")
      ->check(CLI::ExistingFile);
  if (with_log) group->add_option("--log", log, "LCM event log of sensor data")->check(CLI::ExistingFile);
  group->require_option(1);
}

std::unique_ptr<io::SensorSource> SensorInput::open() const {
  try {
    if (!euroc.empty()) return std::make_unique<io::EurocSource>(std::make_shared<io::EurocDataset>(euroc));
    if (!rosbag.empty()) return std::make_unique<io::RosbagReader>(rosbag);
    return std::make_unique<pipeline::LcmLogSource>(log);
  } catch (const std::runtime_error& e) {
    throw CommandError(e.what(), 2);
  }
}

}  // namespace dynavins::cli
