#pragma once
// The feature tracker's output for one stereo frame: what the estimator consumes. Plain data.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace dynavins {

/// One feature of the current left image, with its stereo observation when the right image has one.
struct TrackedFeature {
  int64_t id = -1;       ///< persistent across frames while the track lives; never reused
  int track_length = 0;  ///< frames the feature has been seen in, this one included (1 = new)
  Eigen::Vector2d px = Eigen::Vector2d::Zero();           ///< left pixel (distorted image)
  Eigen::Vector2d px_velocity = Eigen::Vector2d::Zero();  ///< left pixel motion [px/s]; 0 when new
  Eigen::Vector3d bearing = Eigen::Vector3d::UnitZ();     ///< unit bearing in cam0 (undistorted)
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();           ///< bearing on the z = 1 plane (VINS' un_pts)
  bool has_right = false;
  Eigen::Vector2d px_right = Eigen::Vector2d::Zero();        ///< right pixel, valid when has_right
  Eigen::Vector3d bearing_right = Eigen::Vector3d::UnitZ();  ///< unit bearing in cam1, when has_right
  Eigen::Vector2d xy_right = Eigen::Vector2d::Zero();        ///< z = 1 plane in cam1, when has_right
  /// Simulator label at the left pixel (-1 unknown, 0 static, k moving object k). Scoring only:
  /// the estimator must never read it.
  int8_t sim_label = -1;
};

/// Counters of one process() call, for logs and benches.
struct TrackerStats {
  int tracked = 0;        ///< features carried over from the previous frame
  int lost_flow = 0;      ///< KLT failed or left the image
  int lost_back = 0;      ///< failed the forward-backward check
  int lost_patch = 0;     ///< its first patch aligned away from the KLT answer (patch_refine)
  int patch_recaptured = 0;  ///< first patch taken again: it no longer aligned, or changed size
  int lost_ransac = 0;    ///< rejected by the fundamental-matrix RANSAC (off by default)
  int lost_mask = 0;      ///< dropped for crowding a longer track (min_dist)
  int uncounted = 0;      ///< tracks the estimator rejected, kept beside max_cnt (StereoTracker::set_rejected)
  int detected = 0;       ///< new corners
  int stereo = 0;         ///< features with a right observation
  int predicted = 0;      ///< features whose KLT started from the IMU-rotation prediction
};

struct TrackedFrame {
  int64_t t_ns = 0;
  int64_t seq = 0;
  std::vector<TrackedFeature> features;
  TrackerStats stats;
  int64_t received_ns = 0;  ///< steady clock when the tracker took the frame (latency accounting only)
  cv::Mat image;  // left image (shallow copy), for keyframes
};

}  // namespace dynavins
