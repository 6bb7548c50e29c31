#pragma once
// The recorded-input options shared by `convert`, `replay` and later `run`:
// exactly one of --euroc DIR, --rosbag FILE.bag, --log FILE.lcmlog.

#include <memory>
#include <string>

#include "io/sensor_source.hpp"

namespace CLI {
class App;
}

namespace dynavins::cli {

struct SensorInput {
  std::string euroc;
  std::string log;
  std::string rosbag;

  /// Adds the options to `cmd`, mutually exclusive, one required.
  void add_options(CLI::App& cmd, bool with_log);
  /// Opens the chosen input; throws CommandError (exit 2) on bad input, and when `need_stereo` and an
  /// EuRoC folder has no cam1 (a stereo run must not quietly become a mono one).
  std::unique_ptr<io::SensorSource> open(bool need_stereo = false) const;
};

}  // namespace dynavins::cli
