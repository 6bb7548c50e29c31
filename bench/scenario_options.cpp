#include "bench/scenario_options.hpp"

#include <unistd.h>

#include <filesystem>

namespace dynavins::bench {

EstimatorOptions scenarioEstimatorOptions(const sim::Scenario& scenario) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("dynavins_scenario_config_" + std::to_string(::getpid()));
  io::write_vins_stereo_config(dir.string(), sim::vins_config(scenario));
  EstimatorOptions opt = EstimatorOptions::load((dir / "vins_config.yaml").string());
  fs::remove_all(dir);  // the camera models are loaded; the files are no longer needed
  return opt;
}

}  // namespace dynavins::bench
