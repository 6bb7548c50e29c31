#include "sim/scenario/scenario_config.hpp"

#include <unistd.h>

#include <filesystem>

namespace dynavins::sim {

EstimatorOptions scenario_estimator_options(const Scenario& scenario) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("dynavins_scenario_config_" + std::to_string(::getpid()));
  io::write_vins_stereo_config(dir.string(), vins_config(scenario));
  EstimatorOptions opt = EstimatorOptions::load((dir / "vins_config.yaml").string());
  fs::remove_all(dir);  // the camera models are loaded; the files are no longer needed
  return opt;
}

}  // namespace dynavins::sim
