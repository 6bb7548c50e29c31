// RayTable / distortion model: inversion converges everywhere and round-trips through OpenCV's projection.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "sim/render/camera_rays.hpp"

using namespace dynavins::sim;

namespace {

// Largest distance between each pixel and the cv::projectPoints image of its table bearing.
double max_round_trip_error(const CameraIntrinsics& cam, const RayTable& rays, int stride) {
  std::vector<cv::Point3d> pts;
  std::vector<cv::Point2d> px;
  for (int v = 0; v < cam.height; v += stride) {
    for (int u = 0; u < cam.width; u += stride) {
      const int i = v * cam.width + u;
      pts.emplace_back(rays.x(i), rays.y(i), 1.0);
      px.emplace_back(u, v);
    }
  }
  // Always include the four corners, where the inversion is hardest.
  for (int v : {0, cam.height - 1}) {
    for (int u : {0, cam.width - 1}) {
      const int i = v * cam.width + u;
      pts.emplace_back(rays.x(i), rays.y(i), 1.0);
      px.emplace_back(u, v);
    }
  }
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  const cv::Vec4d dist(cam.k1, cam.k2, cam.p1, cam.p2);
  std::vector<cv::Point2d> proj;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist, proj);
  double worst = 0.0;
  for (size_t k = 0; k < px.size(); ++k) worst = std::max(worst, cv::norm(proj[k] - px[k]));
  return worst;
}

}  // namespace

TEST_CASE("RayTable: the distortion inversion converges at every pixel, corners included", "[render][rays]") {
  const CameraIntrinsics cam;
  const RayTable rays(cam);
  CHECK(rays.all_converged());
  CHECK(rays.max_residual_px() < 1e-6);
  // The corner bearings lie further out than the distorted ones (barrel distortion, k1 < 0).
  const int corner = 0;
  CHECK(std::abs(rays.x(corner)) > std::abs((0.0 - cam.cx) / cam.fx));
}

TEST_CASE("RayTable: bearings re-project onto their pixels through cv::projectPoints", "[render][rays]") {
  const CameraIntrinsics cam;
  const RayTable rays(cam);
  const double worst = max_round_trip_error(cam, rays, 1);
  INFO("max round-trip error " << worst << " px");
  CHECK(worst < 0.01);

  CameraIntrinsics strong = cam;  // a wide-angle-like lens
  strong.k1 = -0.38;
  strong.k2 = 0.14;
  strong.p1 = 1e-3;
  strong.p2 = -8e-4;
  const RayTable rays_strong(strong);
  CHECK(rays_strong.all_converged());
  CHECK(max_round_trip_error(strong, rays_strong, 3) < 0.01);
}

TEST_CASE("project_point agrees with cv::projectPoints", "[render][rays]") {
  const CameraIntrinsics cam;
  std::vector<cv::Point3d> pts;
  for (int k = 0; k < 200; ++k) {
    const double z = 1.0 + 0.37 * k;
    pts.emplace_back(std::sin(1.3 * k) * 0.7 * z, std::cos(0.7 * k) * 0.45 * z, z);
  }
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  std::vector<cv::Point2d> proj;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, cv::Vec4d(cam.k1, cam.k2, cam.p1, cam.p2), proj);
  for (size_t k = 0; k < pts.size(); ++k) {
    const Eigen::Vector2d p = project_point(cam, Eigen::Vector3d(pts[k].x, pts[k].y, pts[k].z));
    CHECK(std::abs(p.x() - proj[k].x) < 1e-9);
    CHECK(std::abs(p.y() - proj[k].y) < 1e-9);
  }
}

TEST_CASE("RayTable: stored derivatives match finite differences of the table", "[render][rays]") {
  const CameraIntrinsics cam;
  const RayTable rays(cam);
  const int W = cam.width;
  double worst = 0.0;
  for (int v = 1; v < cam.height - 1; v += 17) {
    for (int u = 1; u < W - 1; u += 13) {
      const int i = v * W + u;
      const double fd_xu = 0.5 * (rays.x(i + 1) - rays.x(i - 1));
      const double fd_yv = 0.5 * (rays.y(i + W) - rays.y(i - W));
      const double fd_xv = 0.5 * (rays.x(i + W) - rays.x(i - W));
      const double fd_yu = 0.5 * (rays.y(i + 1) - rays.y(i - 1));
      worst = std::max({worst, std::abs(fd_xu - rays.dxdu(i)) * cam.fx, std::abs(fd_yv - rays.dydv(i)) * cam.fy,
                        std::abs(fd_xv - rays.dxdv(i)) * cam.fx, std::abs(fd_yu - rays.dydu(i)) * cam.fy});
    }
  }
  INFO("worst derivative mismatch (relative to a pinhole pixel step) " << worst);
  CHECK(worst < 1e-3);
}

TEST_CASE("RayTable: without distortion the bearings are the pinhole ones", "[render][rays]") {
  CameraIntrinsics cam;
  cam.k1 = cam.k2 = cam.p1 = cam.p2 = 0.0;
  const RayTable rays(cam);
  for (int v = 0; v < cam.height; v += 41) {
    for (int u = 0; u < cam.width; u += 37) {
      const int i = v * cam.width + u;
      CHECK(rays.x(i) == Approx((u - cam.cx) / cam.fx).margin(1e-6));
      CHECK(rays.y(i) == Approx((v - cam.cy) / cam.fy).margin(1e-6));
    }
  }
}

TEST_CASE("RayTable: cell bounds contain the bearings of their pixels", "[render][rays]") {
  const CameraIntrinsics cam;
  const RayTable rays(cam);
  for (int v = 0; v < cam.height; v += 5) {
    for (int u = 0; u < cam.width; u += 7) {
      const int i = v * cam.width + u;
      const Eigen::Vector4f& b = rays.cell_bounds((v / RayTable::kCell) * rays.cells_u() + u / RayTable::kCell);
      CHECK(rays.x(i) >= b[0]);
      CHECK(rays.x(i) <= b[1]);
      CHECK(rays.y(i) >= b[2]);
      CHECK(rays.y(i) <= b[3]);
    }
  }
}
