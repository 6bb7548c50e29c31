#pragma once
// Top-down (x-y) plot of an estimate against ground truth, drawn with OpenCV into a PNG.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace dynavins::eval {

/// Text and size of the plot.
struct PlotOptions {
  std::string title;                     ///< e.g. "ATE (se3) RMSE 0.0135 m, 785 pairs"
  std::string gt_label = "ground truth";
  std::string est_label = "estimate";
  int width = 1200;                      ///< image size in pixels
  int height = 900;
};

/// Draws both paths at one common metric scale (x right, y up) with a metre grid, axis labels,
/// start (circle) and end (cross) markers, a legend and the title. Throws std::invalid_argument
/// when both paths are empty or the image is too small to hold the layout.
cv::Mat render_topdown_plot(const std::vector<Eigen::Vector3d>& gt, const std::vector<Eigen::Vector3d>& est,
                            const PlotOptions& options = {});

/// render_topdown_plot() written to a PNG file; throws std::runtime_error naming the path on failure.
void write_topdown_plot(const std::string& png_path, const std::vector<Eigen::Vector3d>& gt,
                        const std::vector<Eigen::Vector3d>& est, const PlotOptions& options = {});

}  // namespace dynavins::eval
