#pragma once
// Top-down (x-y) plot of several aligned estimates against one ground truth, for `dynavins compare`.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace dynavins::eval {

/// One estimated path of the comparison, already in the ground-truth frame.
struct NamedPath {
  std::string label;  ///< legend text, e.g. "high-dynavins  ATE 0.71 m"
  std::vector<Eigen::Vector3d> points;
};

/// Text, size and view of the comparison plot.
struct ComparisonPlotOptions {
  std::string title;
  std::string gt_label = "ground truth";
  int width = 1200;
  int height = 900;
  /// The view covers the ground truth and the estimates, but never more than this many ground-truth
  /// extents (at least 10 m) beyond the ground truth on each side, so one diverged run does not
  /// shrink the others to a dot. Paths leaving the view are clipped; their legend entry says so.
  double max_view_margin = 1.0;
};

/// Colour of path `i` (BGR): a fixed palette that stays apart from the grey ground truth.
cv::Scalar comparison_color(std::size_t i);

/// Draws the ground truth (grey) and every estimate (palette colours, in order) at one metric scale
/// (x right, y up) with a metre grid, start / end markers, a legend and the title. Throws
/// std::invalid_argument when every path is empty, a position is not finite, or the image is
/// smaller than 400 x 300.
cv::Mat render_comparison_plot(const std::vector<Eigen::Vector3d>& gt, const std::vector<NamedPath>& estimates,
                               const ComparisonPlotOptions& options = {});

/// render_comparison_plot() written to a PNG file (via a .partial name, renamed when complete);
/// throws std::runtime_error naming the path on failure.
void write_comparison_plot(const std::string& png_path, const std::vector<Eigen::Vector3d>& gt,
                           const std::vector<NamedPath>& estimates, const ComparisonPlotOptions& options = {});

}  // namespace dynavins::eval
