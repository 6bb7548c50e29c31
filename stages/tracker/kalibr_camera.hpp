#pragma once
// A camera from an EuRoC/Kalibr sensor.yaml (camera_model pinhole, radial-tangential distortion):
// the calibration shipped with the data set itself, next to its images.

#include <string>

#include <Eigen/Geometry>

#include "stages/common/pinhole_radtan_camera.hpp"

namespace dynavins::tracker {

struct KalibrCamera {
  std::shared_ptr<const PinholeRadtanCamera> camera;
  Eigen::Isometry3d T_body_cam = Eigen::Isometry3d::Identity();  ///< T_BS: camera -> body
};

/// Loads `path`; throws ConfigError naming the file and key for a missing key or another model.
KalibrCamera load_kalibr_camera(const std::string& path);

}  // namespace dynavins::tracker
