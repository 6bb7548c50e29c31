#pragma once
// What the keyframe database keeps of a keyframe (paper IV, DESIGN.md §3): its pose, extrinsic, points
// (pixel, normalised coordinates, 3-D point) and one 32-byte ORB descriptor per point, computed once from
// Keyframe::image (the tracked features plus extra Shi-Tomasi corners for place recognition). No image is
// kept: a few tens of kilobytes per keyframe.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "messages/keyframe.hpp"

namespace dynavins::loop {

struct DescriptorOptions {
  int max_points = 400;                  // tracked features + extra corners, at most
  double corner_quality = 0.01;          // Shi-Tomasi threshold, fraction of the strongest corner
  double corner_min_distance_px = 10.0;  // extra corners keep this far from each other and from tracked points
  int border_px = 31;  // ORB's edge threshold: points closer to the border get no descriptor (dropped)
};

/// A keyframe as the database keeps it. Row i of `descriptors` (CV_8UC1, N x 32) describes points[i].
struct KeyframeDescriptors {
  int64_t t_ns = 0;
  int64_t seq = 0;
  Eigen::Vector3d p_wb = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_wb = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_bc = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_bc = Eigen::Quaterniond::Identity();
  std::vector<KeyframePoint> points;
  cv::Mat descriptors;

  /// Heap and inline bytes this entry holds.
  std::size_t memory_bytes() const;
};

/// Maps a distorted pixel to cam0's undistorted z = 1 plane (for the extra corners; tracked features bring
/// their own xy).
using Undistort = std::function<Eigen::Vector2d(const Eigen::Vector2d& px)>;

/// ORB descriptors (upright, one pyramid level) of the keyframe's tracked points and of extra corners
/// detected away from them, up to opts.max_points in all. Points within opts.border_px of the border are
/// dropped. Extra corners get id -1, no 3-D point, and xy from `undistort` (NaN when it is empty: they
/// then serve only the bag of words). Needs a non-empty 8-bit gray `kf.image`.
KeyframeDescriptors compute_keyframe_descriptors(const Keyframe& kf, const DescriptorOptions& opts = {},
                                                 const Undistort& undistort = {});

}  // namespace dynavins::loop
