// comparison_plot: every path appears in its colour, a diverged path does not shrink the view,
// bad input is rejected, and the PNG is written under its name only when complete.
#include "eval/comparison_plot.hpp"
#include "eval/png_output.hpp"

#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <limits>

using namespace dynavins::eval;
namespace fs = std::filesystem;

namespace {

std::vector<Eigen::Vector3d> line_path(double x0, double y0, double x1, double y1) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i <= 100; ++i) p.emplace_back(x0 + (x1 - x0) * i / 100.0, y0 + (y1 - y0) * i / 100.0, 0.0);
  return p;
}

int count_colour(const cv::Mat& img, const cv::Scalar& bgr, int tol = 10) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      bool same = true;
      for (int k = 0; k < 3; ++k) same = same && std::abs(c[k] - static_cast<int>(bgr[k])) <= tol;
      n += same;
    }
  }
  return n;
}

}  // namespace

TEST_CASE("render_comparison_plot draws every path in its own colour", "[eval][plot]") {
  const auto gt = line_path(0, 0, 20, 0);
  const std::vector<NamedPath> est = {{"a", line_path(0, 2, 20, 2)}, {"b", line_path(0, -2, 20, -2)}};
  ComparisonPlotOptions o;
  o.title = "two runs";
  const cv::Mat img = render_comparison_plot(gt, est, o);
  REQUIRE(img.size() == cv::Size(o.width, o.height));
  CHECK(comparison_color(0) != comparison_color(1));
  CHECK(count_colour(img, comparison_color(0)) > 300);
  CHECK(count_colour(img, comparison_color(1)) > 300);
  CHECK(count_colour(img, cv::Scalar(120, 120, 120)) > 300);
  CHECK(count_colour(img, comparison_color(2)) == 0);
}

TEST_CASE("a diverged run is clipped instead of shrinking the others", "[eval][plot]") {
  const auto gt = line_path(0, 0, 20, 0);
  const auto good = line_path(0, 1, 20, 1);
  const std::vector<NamedPath> est = {{"good", good}, {"diverged", line_path(0, 0, 5000, 5000)}};
  const cv::Mat img = render_comparison_plot(gt, est);
  // The good path still spans a good part of the width (it would be a dot at a 5 km scale).
  const cv::Mat mask = [&] {
    cv::Mat m;
    cv::inRange(img, comparison_color(0) - cv::Scalar::all(10), comparison_color(0) + cv::Scalar::all(10), m);
    return m;
  }();
  std::vector<cv::Point> pts;
  cv::findNonZero(mask, pts);
  REQUIRE(!pts.empty());
  const cv::Rect r = cv::boundingRect(pts);
  CHECK(r.width > 250);
}

TEST_CASE("render_comparison_plot rejects bad input", "[eval][plot]") {
  CHECK_THROWS_AS(render_comparison_plot({}, {}), std::invalid_argument);
  CHECK_THROWS_AS(render_comparison_plot({}, {{"empty", {}}}), std::invalid_argument);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(render_comparison_plot(line_path(0, 0, 1, 1), {{"bad", {Eigen::Vector3d(nan, 0, 0)}}}),
                  std::invalid_argument);
  ComparisonPlotOptions tiny;
  tiny.width = 100;
  CHECK_THROWS_AS(render_comparison_plot(line_path(0, 0, 1, 1), {}, tiny), std::invalid_argument);
}

TEST_CASE("write_comparison_plot writes a PNG and leaves no .partial", "[eval][plot]") {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_comparison_plot";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path png = dir / "cmp.png";
  write_comparison_plot(png.string(), line_path(0, 0, 5, 5), {{"a", line_path(0, 0, 5, 4)}});
  CHECK(fs::exists(png));
  CHECK(!fs::exists(dir / "cmp.png.partial"));
  CHECK(cv::imread(png.string()).cols == 1200);
  CHECK_THROWS_WITH(write_comparison_plot((dir / "cmp.jpg").string(), line_path(0, 0, 1, 1), {}),
                    Catch::Contains("cmp.jpg"));
  CHECK_THROWS_WITH(write_png_atomically((dir / "missing" / "x.png").string(), cv::Mat(4, 4, CV_8UC3)),
                    Catch::Contains("x.png"));
  fs::remove_all(dir);
}
