#pragma once
// The simulator's true depth under a sub-pixel image point, for scoring tracks against the truth.

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace dynavins::bench {

/// Bilinear depth [m] of a CV_32F depth image at `px`; none near the border, on a depth edge (the
/// 4x4 neighbourhood spans more than 5 %: the corner's point is ambiguous there), or on the sky.
inline std::optional<double> true_depth(const cv::Mat& depth, const Eigen::Vector2d& px) {
  const int c = static_cast<int>(std::floor(px.x())), r = static_cast<int>(std::floor(px.y()));
  if (r < 1 || c < 1 || r + 2 >= depth.rows || c + 2 >= depth.cols) return std::nullopt;
  float lo = 1e9f, hi = 0.f;
  for (int dr = -1; dr <= 2; ++dr)
    for (int dc = -1; dc <= 2; ++dc) lo = std::min(lo, depth.at<float>(r + dr, c + dc)), hi = std::max(hi, depth.at<float>(r + dr, c + dc));
  if (!(lo > 0) || hi > 1.05f * lo || hi > 1e3f) return std::nullopt;
  const double a = px.x() - c, b = px.y() - r;
  return (1 - a) * (1 - b) * depth.at<float>(r, c) + a * (1 - b) * depth.at<float>(r, c + 1) +
         (1 - a) * b * depth.at<float>(r + 1, c) + a * b * depth.at<float>(r + 1, c + 1);
}

}  // namespace dynavins::bench
