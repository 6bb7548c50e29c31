#pragma once
// Shi-Tomasi corners under a mask, cv::goodFeaturesToTrack's algorithm (threshold relative to the
// strongest corner in the unmasked part, 3x3 non-maximum suppression, greedy minimum distance on a
// grid) without its per-call allocations of candidate lists the size of the image, and with the
// response computed only round the unmasked pixels (the same numbers).

#include <vector>

#include <opencv2/core/mat.hpp>

namespace dynavins::tracker {

/// Buffers detect_corners reuses from call to call: they are image-sized, and fresh ones cost page
/// faults on every call.
struct CornerScratch {
  cv::Mat dx, dy, eig;
  std::vector<float> products, terms;
  std::vector<double> rows;
};

/// Up to `max_corners` corners of `gray` (8-bit) where `mask` is non-zero, strongest first, each at
/// least `min_distance` px from the others; `quality` is the fraction of the strongest unmasked
/// minimum eigenvalue a corner needs. `scratch` (optional) keeps the buffers for the next call.
std::vector<cv::Point2f> detect_corners(const cv::Mat& gray, const cv::Mat& mask, int max_corners, double quality,
                                        double min_distance, CornerScratch* scratch = nullptr);

}  // namespace dynavins::tracker
