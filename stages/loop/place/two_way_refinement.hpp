#pragma once
// Refines a verified loop's relative camera pose with both keyframes' 3-D points (ours, not in the paper or
// VINS-Fusion): PnP RANSAC places the query camera against the match keyframe's points only, so its
// result carries the error of those points' depths (stereo depth at ~5 m is off by centimetres per point,
// and a loop of ~20 inliers then by 1-5 cm). The query keyframe has 3-D points of its own, triangulated
// independently, for many of the same matches; reprojecting them into the match image as well gives the
// pose twice the independent depth information.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynavins::loop {

/// One inlier correspondence between the match camera C_m and the query camera C_k.
struct TwoWayCorrespondence {
  Eigen::Vector3d p_m;       ///< the match keyframe's 3-D point, in C_m
  Eigen::Vector2d xy_k;      ///< its observation in the query image (undistorted, z = 1 plane)
  bool has_p_k = false;      ///< the query keyframe has its own 3-D point for this feature
  Eigen::Vector3d p_k;       ///< that point, in C_k
  Eigen::Vector2d xy_m;      ///< the feature's observation in the match image (z = 1 plane)
};

struct TwoWayRefinementOptions {
  double focal_px = 460.0;   ///< residuals in pixels, for the loss scale
  double huber_px = 1.0;     ///< Huber loss on each reprojection residual [px]
  int max_iterations = 20;
};

/// Refines q_km, t_km (x_k = q_km * x_m + t_km, from PnP) in place over both directions' reprojection
/// errors. Returns false (pose unchanged) when fewer than 3 correspondences or the solve is unusable.
bool refine_two_way(const std::vector<TwoWayCorrespondence>& c, Eigen::Quaterniond& q_km, Eigen::Vector3d& t_km,
                    const TwoWayRefinementOptions& options = {});

}  // namespace dynavins::loop
