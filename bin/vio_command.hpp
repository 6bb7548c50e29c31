#pragma once
// What `run` and `live` share: their estimator options on the command line, turning them into
// VioRunOptions, and running the pipeline into an output folder with the end-of-run summary.

#include <functional>
#include <string>
#include <vector>

#include "io/sensor_source.hpp"
#include "pipeline/vio/run_outputs.hpp"
#include "pipeline/vio/vio_pipeline.hpp"

namespace CLI {
class App;
}

namespace dynavins::cli {

struct VioCommandOptions {
  std::string config;
  std::string out;
  std::string ba = "dynavins";
  bool mono = false;
  std::vector<std::string> set;
  double imu_rate_hz = 200.0;
  bool gyro_prediction = false;
  std::string lcm_url;
  std::vector<std::string> channels;  ///< output channel overrides, key=NAME
  std::string loop = "dynavins";      ///< off | all | switchable | dynavins
  std::string vocabulary;             ///< empty: the default vocabulary (default_vocabulary_path())
  int realtime_priority = pipeline::VioRunOptions{}.realtime_priority;  ///< real time: IMU + publisher

  /// Adds --config, --out, --ba, --mono, --gyro-prediction, --set, --imu-rate, --lcm-url, --channel,
  /// --loop, --vocabulary, --rt-priority.
  void add_options(CLI::App& cmd, const std::string& lcm_url_help);
  /// The run's options (config loaded, overrides applied, checked); CommandError (exit 2) naming the
  /// problem otherwise.
  pipeline::VioRunOptions load(double rate) const;
};

/// The shipped vocabulary: installed (<prefix>/share/dynavins/default_vocabulary.bin next to bin/) or
/// in the source tree (data/vocabulary/default_vocabulary.bin).
std::string default_vocabulary_path();

/// What SIGINT means: for `run` the recording was not processed to its end (exit 130 after the outputs
/// are written, marked interrupted); for `live` it is how a run ends.
enum class InterruptIs { Failure, NormalEnd };

/// Runs `source` into `out_dir` (odometry, features, events, summary.json), prints the summary and, if
/// given, `extra_summary` after it. CommandError on a failed run or one that estimated no pose (exit 1,
/// summary ok: false), outputs that cannot be made (exit 2), or an interrupt that is a failure (130).
void run_vio_with_outputs(io::SensorSource& source, const pipeline::VioRunOptions& options,
                          const pipeline::RunDescription& what, const std::string& out_dir, InterruptIs interrupt,
                          const std::function<void()>& extra_summary = {});

}  // namespace dynavins::cli
