// Camera models: lift/project round trips over the image, analytic Jacobians, and agreement with
// OpenCV's own implementations of the same lenses.

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#ifdef DYNAVINS_HAVE_OMNIDIR
#include <opencv2/ccalib/omnidir.hpp>
#endif

#include "stages/common/camera_loader.hpp"
#include "stages/common/kannala_brandt_camera.hpp"
#include "stages/common/mei_camera.hpp"
#include "stages/common/pinhole_radtan_camera.hpp"

using namespace dynavins;

namespace {

const std::string kEuroc = std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/";

// A fisheye as camodocs calibrates one (k2..k5 = cv::fisheye k1..k4), ~190 degree field of view.
KannalaBrandtCamera::Params fisheye_params() {
  KannalaBrandtCamera::Params p;
  p.width = 640;
  p.height = 480;
  p.k2 = -0.013;
  p.k3 = 0.0031;
  p.k4 = -0.0012;
  p.k5 = 0.00021;
  p.mu = 190.0;
  p.mv = 189.5;
  p.u0 = 321.3;
  p.v0 = 238.7;
  return p;
}

std::vector<Eigen::Vector2d> pixel_grid(const CameraModel& cam, int step = 16) {
  std::vector<Eigen::Vector2d> out;
  for (int v = 0; v <= cam.height(); v += step)
    for (int u = 0; u <= cam.width(); u += step) out.emplace_back(u, v);
  return out;
}

// Largest pixel error of project(lift(p)) over the grid, counting only pixels that lift to a ray.
double round_trip_error(const CameraModel& cam, int* lifted) {
  double worst = 0;
  *lifted = 0;
  for (const auto& px : pixel_grid(cam)) {
    const Eigen::Vector3d b = cam.lift(px);
    if (!b.allFinite()) continue;
    ++*lifted;
    CHECK(b.norm() == Approx(1.0).epsilon(1e-12));
    worst = std::max(worst, (cam.project(b * 3.7) - px).norm());  // any depth along the ray
  }
  return worst;
}

void check_jacobian(const CameraModel& cam, const Eigen::Vector3d& P) {
  CameraModel::Jacobian J;
  cam.project(P, &J);
  CameraModel::Jacobian Jn;
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d dp = Eigen::Vector3d::Zero();
    dp(i) = h;
    Jn.col(i) = (cam.project(P + dp) - cam.project(P - dp)) / (2 * h);
  }
  INFO(cam.name() << " at " << P.transpose() << "\nanalytic\n" << J << "\nnumeric\n" << Jn);
  CHECK((J - Jn).norm() < 1e-5 * std::max(1.0, Jn.norm()));
}

std::vector<Eigen::Vector3d> points_in_view(const CameraModel& cam) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& px : pixel_grid(cam, 64)) {
    const Eigen::Vector3d b = cam.lift(px);
    if (b.allFinite()) out.push_back(b * 2.5);
  }
  return out;
}

}  // namespace

TEST_CASE("lift and project round-trip over the whole image for every model", "[camera]") {
  for (const char* file : {"cam0_pinhole.yaml", "cam1_pinhole.yaml", "cam0_mei.yaml", "cam1_mei.yaml"}) {
    const auto cam = load_camera(kEuroc + file);
    int lifted = 0;
    const double err = round_trip_error(*cam, &lifted);
    INFO(file << " " << cam->describe());
    CHECK(err < 1e-6);
    // Even cam0_mei (xi = 3.6, which has a horizon inside the model) sees a ray at every pixel.
    CHECK(lifted == static_cast<int>(pixel_grid(*cam).size()));
  }
  const KannalaBrandtCamera fisheye(fisheye_params());
  int lifted = 0;
  CHECK(round_trip_error(fisheye, &lifted) < 1e-6);
  CHECK(lifted == static_cast<int>(pixel_grid(fisheye).size()));
  // The corners of this fisheye look backwards: bearings with z < 0 must still round-trip.
  CHECK(fisheye.lift({0.0, 0.0}).z() < 0);
}

TEST_CASE("analytic projection Jacobians match numeric differentiation", "[camera]") {
  const auto pin = load_camera(kEuroc + "cam0_pinhole.yaml");
  const auto mei0 = load_camera(kEuroc + "cam0_mei.yaml");
  const auto mei1 = load_camera(kEuroc + "cam1_mei.yaml");
  const KannalaBrandtCamera kb(fisheye_params());
  for (const CameraModel* cam : {pin.get(), mei0.get(), mei1.get(), static_cast<const CameraModel*>(&kb)})
    for (const auto& P : points_in_view(*cam)) check_jacobian(*cam, P);
  // On the optical axis, where the fisheye switches to its pinhole limit.
  check_jacobian(kb, {0.0, 0.0, 2.0});
  check_jacobian(kb, {1e-7, -2e-7, 2.0});
}

TEST_CASE("pinhole-radtan agrees with cv::projectPoints and cv::undistortPoints", "[camera][opencv]") {
  const auto cam = load_camera(kEuroc + "cam0_pinhole.yaml");
  const auto& p = dynamic_cast<const PinholeRadtanCamera&>(*cam).params();
  const cv::Matx33d K(p.fx, 0, p.cx, 0, p.fy, p.cy, 0, 0, 1);
  const cv::Vec4d D(p.distortion.k1, p.distortion.k2, p.distortion.p1, p.distortion.p2);

  std::vector<cv::Point3d> obj;
  for (const auto& P : points_in_view(*cam)) obj.emplace_back(P.x(), P.y(), P.z());
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, img);
  for (std::size_t i = 0; i < obj.size(); ++i) {
    const Eigen::Vector2d ours = cam->project({obj[i].x, obj[i].y, obj[i].z});
    CHECK((ours - Eigen::Vector2d(img[i].x, img[i].y)).norm() < 1e-9);
  }

  std::vector<cv::Point2d> px, und;
  for (const auto& q : pixel_grid(*cam, 32)) px.emplace_back(q.x(), q.y());
  cv::undistortPoints(px, und, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  double worst = 0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d ours = cam->lift_normalized({px[i].x, px[i].y});
    worst = std::max(worst, (ours - Eigen::Vector2d(und[i].x, und[i].y)).norm());
  }
  CHECK(worst < 1e-6);
}

TEST_CASE("Kannala-Brandt agrees with cv::fisheye", "[camera][opencv]") {
  const auto p = fisheye_params();
  const KannalaBrandtCamera cam(p);
  const cv::Matx33d K(p.mu, 0, p.u0, 0, p.mv, p.v0, 0, 0, 1);
  const cv::Vec4d D(p.k2, p.k3, p.k4, p.k5);
  std::vector<cv::Point3d> obj;
  // cv::fisheye works through x/z, so only points in front of the camera compare.
  for (const auto& P : points_in_view(cam))
    if (P.z() > 0.05) obj.emplace_back(P.x(), P.y(), P.z());
  REQUIRE(obj.size() > 20);
  std::vector<cv::Point2d> img;
  cv::fisheye::projectPoints(obj, img, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  for (std::size_t i = 0; i < obj.size(); ++i) {
    const Eigen::Vector2d ours = cam.project({obj[i].x, obj[i].y, obj[i].z});
    CHECK((ours - Eigen::Vector2d(img[i].x, img[i].y)).norm() < 1e-9);
  }
  std::vector<cv::Point2d> px, und;
  for (const auto& P : obj) {
    const Eigen::Vector2d q = cam.project({P.x, P.y, P.z});
    if ((q - Eigen::Vector2d(p.u0, p.v0)).norm() < 250) px.emplace_back(q.x(), q.y());  // within ~100 deg FOV
  }
  cv::fisheye::undistortPoints(px, und, K, D, cv::noArray(), cv::noArray(),
                               cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
  for (std::size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d ours = cam.lift_normalized({px[i].x, px[i].y});
    CHECK((ours - Eigen::Vector2d(und[i].x, und[i].y)).norm() < 1e-6 * std::max(1.0, ours.norm()));
  }
}

TEST_CASE("MEI agrees with the unified model (cv::omnidir when available)", "[camera][opencv]") {
  for (const char* file : {"cam0_mei.yaml", "cam1_mei.yaml"}) {
    const auto cam = load_camera(kEuroc + file);
    const auto& p = dynamic_cast<const MeiCamera&>(*cam).params();
    const auto pts = points_in_view(*cam);
    REQUIRE(pts.size() > 20);
#ifdef DYNAVINS_HAVE_OMNIDIR
    std::vector<cv::Vec3d> obj;
    for (const auto& P : pts) obj.emplace_back(P.x(), P.y(), P.z());
    const cv::Matx33d K(p.gamma1, 0, p.u0, 0, p.gamma2, p.v0, 0, 0, 1);  // camodocs has no skew
    const cv::Vec4d D(p.distortion.k1, p.distortion.k2, p.distortion.p1, p.distortion.p2);
    std::vector<cv::Vec2d> img;
    cv::omnidir::projectPoints(obj, img, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, p.xi, D);
    for (std::size_t i = 0; i < pts.size(); ++i)
      CHECK((cam->project(pts[i]) - Eigen::Vector2d(img[i][0], img[i][1])).norm() < 1e-8);
#endif
    // Independent formula (Mei & Rives 2007, eq. 1-4), written out with plain doubles.
    for (const auto& P : pts) {
      const double n = std::sqrt(P.x() * P.x() + P.y() * P.y() + P.z() * P.z());
      const double x = P.x() / n / (P.z() / n + p.xi), y = P.y() / n / (P.z() / n + p.xi);
      const double r2 = x * x + y * y, rad = 1 + p.distortion.k1 * r2 + p.distortion.k2 * r2 * r2;
      const double xd = x * rad + 2 * p.distortion.p1 * x * y + p.distortion.p2 * (r2 + 2 * x * x);
      const double yd = y * rad + p.distortion.p1 * (r2 + 2 * y * y) + 2 * p.distortion.p2 * x * y;
      const Eigen::Vector2d expect(p.gamma1 * xd + p.u0, p.gamma2 * yd + p.v0);
      CHECK((cam->project(P) - expect).norm() < 1e-8);
    }
  }
}

TEST_CASE("camera files: a KANNALA_BRANDT file loads, bad ones name file and key", "[camera][loader]") {
  const auto dir = std::filesystem::temp_directory_path() / ("dynavins_cam_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string kb = write("kb.yaml",
                               "%YAML:1.0\n---\nmodel_type: KANNALA_BRANDT\ncamera_name: camera\nimage_width: 640\n"
                               "image_height: 480\nprojection_parameters:\n   k2: -0.013\n   k3: 0.0031\n"
                               "   k4: -0.0012\n   k5: 0.00021\n   mu: 190.0\n   mv: 189.5\n   u0: 321.3\n   v0: 238.7\n");
  const auto cam = load_camera(kb);
  CHECK(cam->name() == "KANNALA_BRANDT");
  CHECK(cam->width() == 640);
  CHECK((cam->project({0.3, -0.2, 1.0}) - KannalaBrandtCamera(fisheye_params()).project({0.3, -0.2, 1.0})).norm() < 1e-12);

  const std::string bad_model = write("bad_model.yaml", "%YAML:1.0\n---\nmodel_type: SCARAMUZZA\nimage_width: 640\nimage_height: 480\n");
  CHECK_THROWS_WITH(load_camera(bad_model), Catch::Contains(bad_model) && Catch::Contains("model_type") &&
                                                Catch::Contains("SCARAMUZZA"));
  const std::string no_fx = write("no_fx.yaml",
                                  "%YAML:1.0\n---\nmodel_type: PINHOLE\nimage_width: 640\nimage_height: 480\n"
                                  "distortion_parameters:\n   k1: 0\n   k2: 0\n   p1: 0\n   p2: 0\n"
                                  "projection_parameters:\n   fy: 300\n   cx: 320\n   cy: 240\n");
  CHECK_THROWS_WITH(load_camera(no_fx), Catch::Contains(no_fx) && Catch::Contains("projection_parameters.fx"));
  std::filesystem::remove_all(dir);
}
