#pragma once
// In-process sensor messages: what the replay driver (or a live LCM source) feeds into the pipeline.
// Plain data, no logic. Time is int64 nanoseconds inside the process (DESIGN.md §3).

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

namespace dynavins {

/// One IMU sample in the body (IMU) frame.
struct ImuSample {
  int64_t t_ns = 0;
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();  ///< specific force [m/s^2]
  Eigen::Vector3d gyr = Eigen::Vector3d::Zero();  ///< angular rate [rad/s]
};

/// A time-matched stereo pair, 8-bit gray. `right` is empty in mono mode.
struct StereoFrame {
  int64_t t_ns = 0;  ///< capture time of the left image
  int64_t seq = 0;   ///< running index assigned by the source, for drop accounting
  cv::Mat left;
  cv::Mat right;
  /// Optional per-pixel label image from the simulator (CV_8U: 0 = static world, k = moving object k).
  cv::Mat labels;
};

/// Ground-truth body state, when the data set carries one.
struct GroundTruthState {
  int64_t t_ns = 0;
  Eigen::Vector3d p_wb = Eigen::Vector3d::Zero();            ///< body position in the world
  Eigen::Quaterniond q_wb = Eigen::Quaterniond::Identity();  ///< body orientation in the world
  Eigen::Vector3d v_wb = Eigen::Vector3d::Zero();            ///< body velocity in the world
  Eigen::Vector3d bias_gyr = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_acc = Eigen::Vector3d::Zero();
  bool has_velocity = false;
  bool has_biases = false;
};

}  // namespace dynavins
