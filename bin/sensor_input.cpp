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

std::unique_ptr<io::SensorSource> SensorInput::open(bool need_stereo) const {
  try {
    if (!euroc.empty()) {
      auto dataset = std::make_shared<io::EurocDataset>(euroc);
      if (need_stereo && !dataset->stereo())
        throw CommandError(euroc + ": no mav0/cam1 folder, but the run is stereo (num_of_cam: 2); pass --mono to "
                           "run on cam0 only", 2);
      return std::make_unique<io::EurocSource>(dataset);
    }
    if (!rosbag.empty()) return std::make_unique<io::RosbagReader>(rosbag);
    return std::make_unique<pipeline::LcmLogSource>(log);
  } catch (const std::runtime_error& e) {
    throw CommandError(e.what(), 2);
  }
}

}  // namespace dynavins::cli
