// Renderer output as a KLT tracker sees it: stereo disparity against the true depth, corner spread over a
// street view, and frame-to-frame flow of static points against their reprojection.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "sim/render/photometric.hpp"
#include "sim/render/renderer.hpp"
#include "sim/render/street_scene.hpp"

using namespace dynavins::sim;

namespace {

const World& static_street() {
  static const World kWorld = [] {
    StreetSceneOptions o;
    o.moving_vehicles = false;
    o.x_max = 100.0;
    return make_street_scene(o);
  }();
  return kWorld;
}

const World& busy_street() {
  static const World kWorld = [] {
    StreetSceneOptions o;
    o.truck_start_x = 5.0;  // truck 8 m ahead at t = 1
    o.x_max = 100.0;
    return make_street_scene(o);
  }();
  return kWorld;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1))];
}

struct DisparityStats {
  int corners = 0, tracked = 0;
  std::vector<double> err;
  std::vector<double> err_smooth;  // corners whose 5x5 neighbourhood has no depth edge (> 5%)
  double within(double tol) const {
    return err.empty() ? 0.0 : static_cast<double>(std::count_if(err.begin(), err.end(), [&](double e) { return e <= tol; })) / err.size();
  }
};

// Tracks left corners into the right image and compares the disparity with fx * b / z from the true depth.
// With distortion, disparity is measured between undistorted (normalised) coordinates, where it is exactly
// b / z for a rectified pair; without, directly in pixels.
DisparityStats stereo_disparity(const Renderer& renderer, const World& world, const Eigen::Isometry3d& T_wl,
                                double baseline, bool photometric) {
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  T_lr.translation().x() = baseline;
  const auto [L, R] = renderer.render_stereo(world, 0.0, T_wl, T_lr);
  cv::Mat left = L.gray, right = R.gray;
  if (photometric) {
    left = apply_photometric(L.gray, PhotometricOptions{}, 0.0, 0);
    right = apply_photometric(R.gray, PhotometricOptions{}, 0.0, 1);
  }
  const CameraIntrinsics& cam = renderer.camera();
  std::vector<cv::Point2f> pl, pr;
  cv::goodFeaturesToTrack(left, pl, 400, 0.01, 10);
  std::vector<uint8_t> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(left, right, pl, pr, status, error, cv::Size(21, 21), 3);
  DisparityStats s;
  s.corners = static_cast<int>(pl.size());
  for (size_t k = 0; k < pl.size(); ++k) {
    const int u = static_cast<int>(std::lround(pl[k].x)), v = static_cast<int>(std::lround(pl[k].y));
    const float z = L.depth.at<float>(v, u);
    if (!status[k] || !std::isfinite(z) || L.labels.at<uint8_t>(v, u) != 0) continue;
    ++s.tracked;
    Eigen::Vector2d xl, xr;
    undistort_pixel(cam, Eigen::Vector2d(pl[k].x, pl[k].y), &xl);
    undistort_pixel(cam, Eigen::Vector2d(pr[k].x, pr[k].y), &xr);
    const double measured = cam.fx * (xl.x() - xr.x());
    const double e = std::abs(measured - cam.fx * baseline / z);
    s.err.push_back(e);
    double lo = z, hi = z;
    for (int dv = -2; dv <= 2; ++dv)
      for (int du = -2; du <= 2; ++du) {
        const float zz = L.depth.at<float>(std::clamp(v + dv, 0, L.depth.rows - 1), std::clamp(u + du, 0, L.depth.cols - 1));
        lo = std::min(lo, static_cast<double>(zz));
        hi = std::max(hi, static_cast<double>(zz));
      }
    if (hi < 1.05 * lo) s.err_smooth.push_back(e);
  }
  return s;
}

void report(const char* what, const DisparityStats& s) {
  std::printf("%s: %d corners, %d static tracked; |disparity error| median %.3f px, p90 %.3f px, "
              "within 0.5 px %.1f%%, within 0.1 px %.1f%%\n",
              what, s.corners, s.tracked, percentile(s.err, 0.5), percentile(s.err, 0.9), 100.0 * s.within(0.5),
              100.0 * s.within(0.1));
  const double smooth_ok = s.err_smooth.empty() ? 0.0
      : static_cast<double>(std::count_if(s.err_smooth.begin(), s.err_smooth.end(), [](double e) { return e <= 0.5; })) /
            s.err_smooth.size();
  std::printf("  of which %zu away from depth edges: median %.3f px, p90 %.3f px, within 0.5 px %.1f%%\n",
              s.err_smooth.size(), percentile(s.err_smooth, 0.5), percentile(s.err_smooth, 0.9), 100.0 * smooth_ok);
}

}  // namespace

TEST_CASE("Stereo: KLT disparity of static corners matches fx * b / depth", "[render][tracking]") {
  const Renderer renderer;
  const Eigen::Isometry3d T_wl = street_camera_pose(4.0, -1.75, 1.5, 0.05, -0.03);
  const DisparityStats s = stereo_disparity(renderer, static_street(), T_wl, 0.11, false);
  report("stereo, EuRoC distortion, noiseless", s);
  REQUIRE(s.tracked > 150);
  CHECK(s.within(0.5) > 0.9);
  CHECK(percentile(s.err, 0.5) < 0.1);

  const DisparityStats n = stereo_disparity(renderer, static_street(), T_wl, 0.11, true);
  report("stereo, EuRoC distortion, default photometric noise", n);
  CHECK(n.within(0.5) > 0.9);

  CameraIntrinsics pinhole;
  pinhole.k1 = pinhole.k2 = pinhole.p1 = pinhole.p2 = 0.0;
  const Renderer r0(pinhole);
  const DisparityStats p = stereo_disparity(r0, static_street(), street_camera_pose(20.0, -1.2, 1.4, -0.1), 0.11, false);
  report("stereo, no distortion (pixel disparity)", p);
  CHECK(p.within(0.5) > 0.9);
}

TEST_CASE("A street view with a truck close ahead has corners all over the image", "[render][tracking]") {
  const Renderer renderer;
  const RenderedView v = renderer.render(busy_street(), 1.0, street_camera_pose(0.0, -1.75, 1.5, 0.03, -0.02));
  const cv::Mat img = apply_photometric(v.gray, PhotometricOptions{}, 1.0);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(img, corners, 150, 0.01, 30);  // VINS-Fusion's front-end settings
  int grid[4][4] = {};
  int on_truck = 0;
  for (const auto& c : corners) {
    grid[std::min(3, static_cast<int>(c.y * 4 / img.rows))][std::min(3, static_cast<int>(c.x * 4 / img.cols))]++;
    if (v.labels.at<uint8_t>(static_cast<int>(c.y), static_cast<int>(c.x)) == 1) ++on_truck;
  }
  int cells = 0;
  std::printf("corners per 4x4 cell (150 max, min distance 30 px):\n");
  for (auto& row : grid) {
    for (int n : row) {
      std::printf(" %3d", n);
      cells += n > 0;
    }
    std::printf("\n");
  }
  const double truck_share = cv::countNonZero(v.labels == 1) / static_cast<double>(v.labels.total());
  std::printf("%zu corners, %d of 16 cells covered, %d on the truck (%.0f%% of the image)\n", corners.size(), cells,
              on_truck, 100.0 * truck_share);
  CHECK(corners.size() >= 140);
  CHECK(cells >= 12);
  CHECK(on_truck > 10);
}

TEST_CASE("Ordinary photometric settings keep a street view off the clipping limits", "[render][tracking]") {
  const Renderer renderer;
  const World& w = busy_street();
  double worst_hi = 0.0, worst_lo = 0.0;
  for (double t : {0.0, 7.0, 15.0, 31.0, 47.0}) {  // across the slow gain drift
    const RenderedView v = renderer.render(w, 1.0, street_camera_pose(-2.0 + 0.5 * t, -1.75, 1.5, 0.3 * std::sin(t), 0.05));
    const cv::Mat img = apply_photometric(v.gray, PhotometricOptions{}, t);
    worst_hi = std::max(worst_hi, cv::countNonZero(img >= 255) / static_cast<double>(img.total()));
    worst_lo = std::max(worst_lo, cv::countNonZero(img <= 0) / static_cast<double>(img.total()));
  }
  std::printf("clipped pixels over the drift: at most %.3f%% white, %.3f%% black\n", 100.0 * worst_hi, 100.0 * worst_lo);
  CHECK(worst_hi < 0.001);
  CHECK(worst_lo < 0.001);
}

TEST_CASE("Frame-to-frame KLT flow of static corners matches their reprojection", "[render][tracking]") {
  // 20 Hz at 3 m/s with a slow turn: the flow a tracker sees, against the geometry of the true depth.
  const Renderer renderer;
  const World& w = static_street();
  const CameraIntrinsics& cam = renderer.camera();
  const Eigen::Isometry3d T0 = street_camera_pose(10.0, -1.75, 1.5, 0.0, 0.0);
  const Eigen::Isometry3d T1 = street_camera_pose(10.15, -1.74, 1.5, 0.01, 0.002);
  const RenderedView a = renderer.render(w, 0.0, T0), b = renderer.render(w, 0.05, T1);
  const cv::Mat ia = apply_photometric(a.gray, PhotometricOptions{}, 0.0), ib = apply_photometric(b.gray, PhotometricOptions{}, 0.05);
  std::vector<cv::Point2f> p0, p1;
  cv::goodFeaturesToTrack(ia, p0, 300, 0.01, 15);
  std::vector<uint8_t> st;
  std::vector<float> er;
  cv::calcOpticalFlowPyrLK(ia, ib, p0, p1, st, er, cv::Size(21, 21), 3);
  const Eigen::Isometry3d T_10 = T1.inverse() * T0;
  std::vector<double> err;
  for (size_t k = 0; k < p0.size(); ++k) {
    const int u = static_cast<int>(std::lround(p0[k].x)), v = static_cast<int>(std::lround(p0[k].y));
    const float z = a.depth.at<float>(v, u);
    if (!st[k] || !std::isfinite(z)) continue;
    Eigen::Vector2d xn;
    undistort_pixel(cam, Eigen::Vector2d(p0[k].x, p0[k].y), &xn);
    const Eigen::Vector3d P1 = T_10 * (z * Eigen::Vector3d(xn.x(), xn.y(), 1.0));
    if (P1.z() <= 0.1) continue;
    const Eigen::Vector2d pred = project_point(cam, P1);
    err.push_back(std::hypot(pred.x() - p1[k].x, pred.y() - p1[k].y));
  }
  const double within = static_cast<double>(std::count_if(err.begin(), err.end(), [](double e) { return e <= 0.5; })) / std::max<size_t>(1, err.size());
  std::printf("temporal KLT: %zu static tracks, |flow - reprojection| median %.3f px, p90 %.3f px, within 0.5 px %.1f%%\n",
              err.size(), percentile(err, 0.5), percentile(err, 0.9), 100.0 * within);
  REQUIRE(err.size() > 150);
  CHECK(within > 0.9);
}
