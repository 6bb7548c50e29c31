#pragma once
// Shi-Tomasi corners under a mask, cv::goodFeaturesToTrack's algorithm (threshold relative to the
// strongest corner in the unmasked part, 3x3 non-maximum suppression, greedy minimum distance on a
// grid) without its per-call allocations of candidate lists the size of the image.

#include <vector>

#include <opencv2/core/mat.hpp>

namespace dynavins {

/// Up to `max_corners` corners of `gray` (8-bit) where `mask` is non-zero, strongest first, each at
/// least `min_distance` px from the others; `quality` is the fraction of the strongest unmasked
/// minimum eigenvalue a corner needs.
std::vector<cv::Point2f> detect_corners(const cv::Mat& gray, const cv::Mat& mask, int max_corners, double quality,
                                        double min_distance);

}  // namespace dynavins
