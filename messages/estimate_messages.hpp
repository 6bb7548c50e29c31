#pragma once
// In-process estimator outputs that every later consumer (IMU propagation, publisher, run outputs) shares.
// Plain data, no logic.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynavins {

/// Where a published pose comes from (mirrors dynavins_lcm::pose_t::source).
enum class PoseSource : int8_t { ImuRate = 0, Window = 1, LoopCorrected = 2 };

/// The navigation state of the body at one instant: the estimator's "latest state" snapshot
/// that the IMU stage propagates at IMU rate.
struct NavState {
  int64_t t_ns = 0;
  Eigen::Vector3d p_wb = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_wb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_wb = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_gyr = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_acc = Eigen::Vector3d::Zero();
};

/// A pose output, tagged with its source.
struct PoseEstimate {
  PoseSource source = PoseSource::Window;
  NavState state;
};

/// One feature of the window with its robust-BA weight (paper III, eq. 10).
struct WeightedFeature {
  int64_t id = 0;
  float u = 0.f, v = 0.f;                                  ///< pixel in the newest left image
  bool has_right = false;                                  ///< the newest observation has a right pixel
  float u_r = 0.f, v_r = 0.f;                              ///< its pixel in the right image, when has_right
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();           ///< triangulated point in the world
  float weight = 1.f;                                      ///< w_j in [0, 1]
  int32_t times_solved = 0;                                ///< n_j
  int8_t sim_label = -1;                                   ///< -1 unknown, 0 static, k moving object k
};

/// The features of one window solve with their weights.
struct WeightedFeatureSet {
  int64_t t_ns = 0;
  std::vector<WeightedFeature> features;
};

}  // namespace dynavins
