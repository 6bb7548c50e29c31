#pragma once
// Writes a stereo-inertial configuration in VINS-Fusion's own yaml format (OpenCV FileStorage,
// camodocs PINHOLE camera files), so that VINS-Fusion itself, the authors' DynaVINS and this
// project all run a generated data set unchanged.

#include <string>

#include <Eigen/Geometry>

namespace dynavins::io {

struct PinholeRadtan {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;
};

struct VinsStereoConfig {
  PinholeRadtan cam0, cam1;
  Eigen::Isometry3d body_T_cam0 = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d body_T_cam1 = Eigen::Isometry3d::Identity();
  // IMU noise as VINS-Fusion users set it: inflated over the sensor's datasheet (its EuRoC config).
  double acc_n = 0.1, gyr_n = 0.01, acc_w = 0.001, gyr_w = 0.0001, g_norm = 9.81;
};

/// Writes `dir`/vins_config.yaml, cam0_pinhole.yaml and cam1_pinhole.yaml. Throws on I/O failure.
void write_vins_stereo_config(const std::string& dir, const VinsStereoConfig& config);

}  // namespace dynavins::io
