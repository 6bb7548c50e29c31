#pragma once
// What the loop closer receives and produces (paper IV, DESIGN.md §2-3). Plain data, no logic.
//
//   estimator --Keyframe--> loop closer --LoopCorrection--> publisher / run outputs
//
// A Keyframe is a frame the window kept, sent once its window estimate is final (when it leaves the
// window, or at the end of the run). Its image travels only as far as the loop stage, which computes the
// descriptors and drops it: the keyframe database keeps no images.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

namespace dynavins {

/// One point of a keyframe: a tracked feature (id >= 0), or an extra corner detected for place
/// recognition only (id == -1, no 3-D point).
struct KeyframePoint {
  int64_t id = -1;                                // the tracker's feature id; -1 for an extra corner
  Eigen::Vector2d px = Eigen::Vector2d::Zero();   // left pixel (distorted image)
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();   // undistorted, on cam0's z = 1 plane
  bool has_p_w = false;                           // the window triangulated it
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();  // world point (odometry frame), when has_p_w
  float weight = 1.f;                             // robust-BA weight w_j (eq. 10)
};

/// A keyframe as the odometry left it.
struct Keyframe {
  int64_t t_ns = 0;
  int64_t seq = 0;  // the tracked frame's seq
  Eigen::Vector3d p_wb = Eigen::Vector3d::Zero();  // body in the odometry world frame
  Eigen::Quaterniond q_wb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_bc = Eigen::Vector3d::Zero();  // cam0 in the body (extrinsic)
  Eigen::Quaterniond q_bc = Eigen::Quaterniond::Identity();
  std::vector<KeyframePoint> points;
  cv::Mat image;  // left gray image; dropped by the loop stage after descriptors are computed
};

/// A verified loop: keyframe `query` (C_k) seen again in the older keyframe `match` (C_m). The relative
/// pose is T_m^k of eq. 13: the query body's pose expressed in the match body's frame.
struct VerifiedLoop {
  int64_t query_t_ns = 0;
  int64_t match_t_ns = 0;
  Eigen::Vector3d p_mq = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_mq = Eigen::Quaterniond::Identity();
  int inliers = 0;
};

}  // namespace dynavins
