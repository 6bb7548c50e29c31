// trajectory_plot: the rendered image contains both paths in their colours and writes as PNG.
#include "eval/trajectory_plot.hpp"

#include <catch2/catch.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <random>

using namespace dynavins::eval;
namespace fs = std::filesystem;

namespace {

std::vector<Eigen::Vector3d> circle(double r, double dx) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i <= 400; ++i) {
    const double a = 2 * M_PI * i / 400.0;
    p.emplace_back(dx + r * std::cos(a), r * std::sin(a), 0.0);
  }
  return p;
}

int count_colour(const cv::Mat& img, const cv::Vec3b& bgr, int tol) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      if (std::abs(c[0] - bgr[0]) <= tol && std::abs(c[1] - bgr[1]) <= tol && std::abs(c[2] - bgr[2]) <= tol) ++n;
    }
  }
  return n;
}

}  // namespace

TEST_CASE("render_topdown_plot draws both paths", "[eval][plot]") {
  PlotOptions o;
  o.title = "ATE (se3) RMSE 0.1 m";
  const cv::Mat img = render_topdown_plot(circle(2.0, 0.0), circle(2.1, 0.3), o);
  REQUIRE(img.type() == CV_8UC3);
  CHECK(img.cols == 1200);
  CHECK(img.rows == 900);
  // Estimate blue (BGR 180,119,31) covers a visible length; the grey ground-truth path adds to
  // the grey already present in text anti-aliasing and the legend.
  const cv::Vec3b blue(180, 119, 31), grey(110, 110, 110);
  CHECK(count_colour(img, blue, 12) > 1500);
  const cv::Mat only_est = render_topdown_plot({}, circle(2.1, 0.3), o);
  CHECK(count_colour(only_est, blue, 12) > 1500);
  CHECK(count_colour(img, grey, 12) - count_colour(only_est, grey, 12) > 1500);
}

TEST_CASE("render_topdown_plot copes with a static trajectory and rejects nothing to draw", "[eval][plot]") {
  const std::vector<Eigen::Vector3d> still(10, Eigen::Vector3d(1, 1, 1));
  CHECK_NOTHROW(render_topdown_plot(still, still));
  CHECK_THROWS_AS(render_topdown_plot({}, {}), std::invalid_argument);
  PlotOptions tiny;
  tiny.width = 100;
  CHECK_THROWS_AS(render_topdown_plot(still, still, tiny), std::invalid_argument);
}

TEST_CASE("write_topdown_plot writes a readable PNG and reports a bad path", "[eval][plot]") {
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("dynavins_test_plot_" + std::to_string(rd()));
  fs::create_directories(dir);
  const std::string png = (dir / "plot.png").string();
  write_topdown_plot(png, circle(1.0, 0.0), circle(1.0, 0.1));
  const cv::Mat back = cv::imread(png);
  CHECK(back.cols == 1200);
  CHECK(back.rows == 900);
  const std::string bad = (dir / "missing_dir" / "plot.png").string();
  CHECK_THROWS_WITH(write_topdown_plot(bad, circle(1.0, 0.0), {}), Catch::Contains(bad));
  const std::string jpg = (dir / "plot.jpg").string();
  CHECK_THROWS_WITH(write_topdown_plot(jpg, circle(1.0, 0.0), {}), Catch::Contains(jpg) && Catch::Contains(".png"));
  CHECK_FALSE(fs::exists(jpg));
  fs::remove_all(dir);
}
