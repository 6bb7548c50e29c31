#pragma once
// Builds a CameraModel from a camodocs calibration yaml (model_type PINHOLE, MEI or KANNALA_BRANDT),
// the files VINS-Fusion's cam0_calib / cam1_calib keys point to.

#include <string>

#include "stages/common/camera_model.hpp"

namespace dynavins {

/// Loads `path`; throws ConfigError naming the file and the bad key (unknown model_type included).
CameraModelPtr load_camera(const std::string& path);

/// Resolves `calib` (the value of `key` in `config_file`) against the config's folder like
/// VINS-Fusion, then loads it; a missing file names both the file and the key that pointed to it.
CameraModelPtr load_camera_from_config(const std::string& config_file, const std::string& key,
                                       const std::string& calib, std::string* resolved_path = nullptr);

}  // namespace dynavins
