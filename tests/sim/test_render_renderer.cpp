// Renderer: depth and labels against independent ray casting, occlusion, sky, determinism, speed.

#include <catch2/catch.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <vector>

#include <Eigen/LU>
#include <opencv2/core.hpp>

#include "sim/render/renderer.hpp"
#include "sim/render/street_scene.hpp"

using namespace dynavins::sim;

namespace {

Eigen::Isometry3d planar(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

TextureDensity coarse() {
  TextureDensity d;
  d.ground_m = 0.1;
  d.building_m = 0.08;
  d.vehicle_m = 0.04;
  return d;
}

// A small scene: ground, two buildings, a wall, a car driving toward +x, a parked truck.
World small_scene() {
  World w(coarse());
  GroundSpec g;
  g.x_min = -20;
  g.x_max = 60;
  g.y_min = -30;
  g.y_max = 30;
  g.tile_m = 20;
  g.layout.roads.push_back(Road{{-30, 0}, {80, 0}, 8.0, true});
  w.add_ground(g);
  w.add_building({25.0, 14.0}, 0.1, 18.0, 8.0, 12.0, 1);
  w.add_building({30.0, -13.0}, -0.05, 14.0, 8.0, 9.0, 2);
  w.add_wall({5.0, -8.0}, {15.0, -8.5}, 2.2, 3);
  w.add_car([](double t) { return planar(8.0 + 2.0 * t, -1.8, 0.0); }, 4);
  w.add_truck([](double) { return planar(22.0, 2.0, 3.1); }, 5);
  return w;
}

struct RefHit {
  double depth = std::numeric_limits<double>::infinity();
  int label = 0;
};

// Independent reference: double-precision undistortion and a brute-force nearest hit over every quad.
RefHit reference(const World& w, double t, const Eigen::Isometry3d& T_wc, const CameraIntrinsics& cam, double u,
                 double v) {
  Eigen::Vector2d xn;
  undistort_pixel(cam, Eigen::Vector2d(u, v), &xn);
  const Eigen::Vector3d o = T_wc.translation();
  const Eigen::Vector3d d = T_wc.linear() * Eigen::Vector3d(xn.x(), xn.y(), 1.0);  // depth = ray parameter
  RefHit best;
  for (const WorldObject& obj : w.objects()) {
    const Eigen::Isometry3d T = obj.pose_at(t);
    for (const Quad& q : obj.quads) {
      Eigen::Matrix3d A;
      A << d, -(T.linear() * q.edge_u), -(T.linear() * q.edge_v);
      const Eigen::Vector3d x = A.fullPivLu().solve(T * q.origin - o);
      if (x[0] > 0.0 && x[1] >= 0.0 && x[1] <= 1.0 && x[2] >= 0.0 && x[2] <= 1.0 && x[0] < best.depth) {
        best = RefHit{x[0], obj.id};
      }
    }
  }
  return best;
}

}  // namespace

TEST_CASE("Renderer: depth and labels match independent ray casting", "[render]") {
  const World w = small_scene();
  const Renderer renderer;
  const CameraIntrinsics& cam = renderer.camera();
  Eigen::Isometry3d T_wc = street_camera_pose(0.0, -1.0, 1.6, 0.12, -0.05);
  T_wc.linear() = T_wc.linear() * Eigen::AngleAxisd(0.04, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // roll
  const double t = 1.5;
  const RenderedView view = renderer.render(w, t, T_wc);
  REQUIRE(view.depth.type() == CV_32FC1);
  REQUIRE(view.labels.type() == CV_8UC1);
  int checked = 0, hits = 0, sky = 0, edge_excused = 0, bad_label = 0;
  double worst_rel = 0.0;
  int label_seen[8] = {0};
  for (int v = 0; v < cam.height; v += 3) {
    for (int u = 0; u < cam.width; u += 3) {
      const RefHit ref = reference(w, t, T_wc, cam, u, v);
      const float z = view.depth.at<float>(v, u);
      const int label = view.labels.at<uint8_t>(v, u);
      ++checked;
      const bool same_label = label == ref.label;
      const bool same_kind = std::isinf(ref.depth) == std::isinf(z);
      const bool same_depth = std::isinf(ref.depth) ? std::isinf(z) : std::abs(z - ref.depth) <= 1e-4 * ref.depth;
      if (!(same_label && same_kind && same_depth)) {
        // A pixel centre within a hair of a silhouette may fall either way (float ray table): excuse it
        // only if the reference itself changes under a 1e-3 px nudge.
        bool on_edge = false;
        for (const auto& [du, dv] : {std::pair{1e-3, 0.0}, {-1e-3, 0.0}, {0.0, 1e-3}, {0.0, -1e-3}}) {
          const RefHit n = reference(w, t, T_wc, cam, u + du, v + dv);
          on_edge = on_edge || n.label != ref.label || std::abs(n.depth - ref.depth) > 1e-3 * ref.depth ||
                    std::isinf(n.depth) != std::isinf(ref.depth);
        }
        if (on_edge) {
          ++edge_excused;
          continue;
        }
        ++bad_label;
        continue;
      }
      if (std::isinf(ref.depth)) {
        ++sky;
        CHECK(label == 0);
      } else {
        ++hits;
        worst_rel = std::max(worst_rel, std::abs(z - ref.depth) / ref.depth);
      }
      label_seen[std::min(label, 7)]++;
    }
  }
  std::printf("depth/labels vs ray casting: %d pixels, %d hits, %d sky, worst relative depth error %.2e, "
              "%d edge pixels excused, %d mismatches; pixels per label 0/1/2: %d/%d/%d\n",
              checked, hits, sky, worst_rel, edge_excused, bad_label, label_seen[0], label_seen[1], label_seen[2]);
  CHECK(bad_label == 0);
  CHECK(edge_excused < checked / 1000 + 2);
  CHECK(worst_rel < 1e-5);
  CHECK(sky > 1000);           // the scene has sky ...
  CHECK(label_seen[1] > 500);  // ... the car ...
  CHECK(label_seen[2] > 500);  // ... and the truck in view
}

TEST_CASE("Renderer: labels at the projections of a moving box's centre and face corners", "[render]") {
  World w(coarse());
  const int car = w.add_car([](double t) { return planar(10.0 + 3.0 * t, 0.3, 0.2); }, 8);
  const Renderer renderer;
  const CameraIntrinsics& cam = renderer.camera();
  const Eigen::Isometry3d T_wc = street_camera_pose(0.0, 0.0, 1.2);
  for (double t : {0.0, 1.0, 2.5}) {
    const RenderedView view = renderer.render(w, t, T_wc);
    const Eigen::Isometry3d T_wo = w.object(car).pose_at(t);
    const Eigen::Isometry3d T_co = T_wc.inverse() * T_wo;
    // Box centre: its projection lies on a visible face.
    const Eigen::Vector2d c = project_point(cam, T_co * Eigen::Vector3d(0, 0, 0.75));
    CHECK(view.labels.at<uint8_t>(static_cast<int>(std::lround(c.y())), static_cast<int>(std::lround(c.x()))) == car);
    // Corners of the back face (x = -2.25), 3% inside: the car; 3% outside: not the car.
    for (double sy : {-1.0, 1.0}) {
      for (double sz : {0.0, 1.0}) {
        const Eigen::Vector3d corner(-2.25, sy * 0.9, sz * 1.5);
        const Eigen::Vector3d inward = Eigen::Vector3d(0, -sy * 0.9, 0.75 - sz * 1.5) * 0.03;
        const Eigen::Vector2d pin = project_point(cam, T_co * (corner + inward));
        const Eigen::Vector2d pout = project_point(cam, T_co * (corner - inward));
        CHECK(view.labels.at<uint8_t>(static_cast<int>(std::lround(pin.y())), static_cast<int>(std::lround(pin.x()))) == car);
        CHECK(view.labels.at<uint8_t>(static_cast<int>(std::lround(pout.y())), static_cast<int>(std::lround(pout.x()))) == 0);
      }
    }
    // Depth at the back face's centre: its distance along the optical axis.
    const Eigen::Vector3d face_centre = T_co * Eigen::Vector3d(-2.25, 0.0, 0.75);
    const Eigen::Vector2d pf = project_point(cam, face_centre);
    const int fu = static_cast<int>(std::lround(pf.x())), fv = static_cast<int>(std::lround(pf.y()));
    Eigen::Vector2d xn;
    undistort_pixel(cam, Eigen::Vector2d(fu, fv), &xn);
    const Eigen::Vector3d n = T_co.linear() * Eigen::Vector3d(-1, 0, 0);
    const double expected = n.dot(face_centre) / n.dot(Eigen::Vector3d(xn.x(), xn.y(), 1.0));
    CHECK(view.depth.at<float>(fv, fu) == Approx(expected).epsilon(1e-5));
  }
}

TEST_CASE("Renderer: a box in front occludes the one behind", "[render]") {
  World w(coarse());
  const int truck = w.add_truck([](double) { return planar(25.0, 0.0, 0.0); }, 1);
  const int car = w.add_car([](double) { return planar(10.0, 0.0, 0.0); }, 2);
  const Renderer renderer;
  const CameraIntrinsics& cam = renderer.camera();
  const Eigen::Isometry3d T_wc = street_camera_pose(0.0, 0.0, 1.0);
  const RenderedView view = renderer.render(w, 0.0, T_wc);
  const Eigen::Isometry3d T_cw = T_wc.inverse();
  // Through the car's back face the car wins, at its depth.
  const Eigen::Vector3d car_back = T_cw * Eigen::Vector3d(10.0 - 2.25, 0.0, 0.8);
  const Eigen::Vector2d p = project_point(cam, car_back);
  const int u = static_cast<int>(std::lround(p.x())), v = static_cast<int>(std::lround(p.y()));
  CHECK(view.labels.at<uint8_t>(v, u) == car);
  CHECK(view.depth.at<float>(v, u) == Approx(car_back.z()).epsilon(1e-3));
  // Above the car's roof the truck's back face shows, further away.
  const Eigen::Vector3d truck_back = T_cw * Eigen::Vector3d(25.0 - 5.0, 0.0, 3.0);
  const Eigen::Vector2d q = project_point(cam, truck_back);
  const int tu = static_cast<int>(std::lround(q.x())), tv = static_cast<int>(std::lround(q.y()));
  CHECK(view.labels.at<uint8_t>(tv, tu) == truck);
  CHECK(view.depth.at<float>(tv, tu) == Approx(truck_back.z()).epsilon(1e-3));
  // Count: the truck is partly hidden, not entirely.
  const int n_truck = cv::countNonZero(view.labels == truck), n_car = cv::countNonZero(view.labels == car);
  CHECK(n_truck > 1000);
  CHECK(n_car > 1000);
}

TEST_CASE("Renderer: silhouettes are anti-aliased, labels follow the pixel centre", "[render]") {
  // A plain upright panel 10 m ahead slides right in quarter-pixel steps against the smooth sky; the
  // pixel its edge crosses must blend gradually, its label flip exactly when the edge passes the centre.
  World w;
  const double fx = CameraIntrinsics{}.fx;
  const double step_m = 0.25 * 10.0 / fx;  // a quarter pixel at 10 m (near the image centre)
  const int id = w.add_object("panel", [step_m](double t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(10.0, -step_m * t, 0.0);
    return T;
  });
  Quad q;  // facing -x (the camera), spanning y in [0, 2] (left of the camera) and z in [0, 3]
  q.origin = Eigen::Vector3d(0.0, 2.0, 0.0);
  q.edge_u = Eigen::Vector3d(0.0, -2.0, 0.0);
  q.edge_v = Eigen::Vector3d(0.0, 0.0, 3.0);
  q.texture = std::make_shared<const MipTexture>(cv::Mat(8, 8, CV_8UC1, cv::Scalar(40)));
  w.add_quad(id, q);
  RenderOptions opt;
  opt.sun_direction = Eigen::Vector3d(-1.0, 0.0, 0.2);  // light the panel's front
  const Renderer renderer(CameraIntrinsics{}, opt);
  const Eigen::Isometry3d T_wc = street_camera_pose(0.0, 0.0, 1.5);
  // The panel's right edge (y = 0 at t = 0) projects near the principal point; watch the pixel just
  // right of it at the row of the principal point.
  const CameraIntrinsics& cam = renderer.camera();
  const int v = static_cast<int>(std::lround(cam.cy));
  const Eigen::Vector2d e0 = project_point(cam, T_wc.inverse() * Eigen::Vector3d(10.0, 0.0, 1.5));
  const int u = static_cast<int>(std::ceil(e0.x()));
  std::vector<double> coverage;
  const RenderedView sky_only = renderer.render(w, -100.0, T_wc);  // panel far out of the way
  const double sky = sky_only.gray.at<uint8_t>(v, u);
  for (int k = 0; k <= 12; ++k) {
    const RenderedView view = renderer.render(w, k, T_wc);
    const double panel = view.gray.at<uint8_t>(v, u - 3);  // well inside the panel
    const double g = view.gray.at<uint8_t>(v, u);
    coverage.push_back((g - sky) / (panel - sky));
    const Eigen::Vector2d e = project_point(cam, T_wc.inverse() * Eigen::Vector3d(10.0, -step_m * k, 1.5));
    // Label and depth belong to the pixel centre: the panel once its edge is past the centre.
    if (std::abs(e.x() - u) > 1e-3) {
      CHECK((view.labels.at<uint8_t>(v, u) == id) == (e.x() > u));
      CHECK(std::isinf(view.depth.at<float>(v, u)) == (e.x() < u));
    }
  }
  int intermediate = 0;
  for (size_t k = 0; k < coverage.size(); ++k) {
    if (k > 0) CHECK(coverage[k] >= coverage[k - 1] - 0.02);  // monotone as the edge advances
    intermediate += coverage[k] > 0.1 && coverage[k] < 0.9;
  }
  std::printf("edge pixel coverage per quarter-pixel step:");
  for (double c : coverage) std::printf(" %.2f", c);
  std::printf("\n");
  CHECK(coverage.front() < 0.05);
  CHECK(coverage.back() > 0.95);
  CHECK(intermediate >= 3);
}

TEST_CASE("Renderer: the sky is infinite, static and featureless", "[render]") {
  World w(coarse());
  const Renderer renderer;
  const RenderedView view = renderer.render(w, 0.0, street_camera_pose(0, 0, 1.5, 0.0, 0.3));
  CHECK(cv::countNonZero(view.labels) == 0);
  for (int v = 0; v < view.depth.rows; v += 31)
    for (int u = 0; u < view.depth.cols; u += 29) CHECK(std::isinf(view.depth.at<float>(v, u)));
  cv::Mat dx, dy;
  cv::absdiff(view.gray.colRange(1, view.gray.cols), view.gray.colRange(0, view.gray.cols - 1), dx);
  cv::absdiff(view.gray.rowRange(1, view.gray.rows), view.gray.rowRange(0, view.gray.rows - 1), dy);
  double mx = 0, my = 0;
  cv::minMaxLoc(dx, nullptr, &mx);
  cv::minMaxLoc(dy, nullptr, &my);
  CHECK(mx <= 1.0);  // a smooth gradient: neighbours differ by at most one quantisation step
  CHECK(my <= 1.0);
  double lo = 0, hi = 0;
  cv::minMaxLoc(view.gray, &lo, &hi);
  CHECK(hi < 240.0);
}

TEST_CASE("Renderer: output is deterministic and render_stereo equals two renders", "[render]") {
  const World w = small_scene();
  const Renderer renderer;
  const Eigen::Isometry3d T_wl = street_camera_pose(1.0, -1.5, 1.5, 0.05);
  Eigen::Isometry3d T_lr = Eigen::Isometry3d::Identity();
  T_lr.translation().x() = 0.11;
  const RenderedView a = renderer.render(w, 0.7, T_wl);
  const RenderedView b = renderer.render(w, 0.7, T_wl);
  CHECK(cv::norm(a.gray, b.gray, cv::NORM_INF) == 0.0);
  const auto [l, r] = renderer.render_stereo(w, 0.7, T_wl, T_lr);
  CHECK(cv::norm(a.gray, l.gray, cv::NORM_INF) == 0.0);
  const RenderedView r2 = renderer.render(w, 0.7, T_wl * T_lr);
  CHECK(cv::norm(r.gray, r2.gray, cv::NORM_INF) == 0.0);
  CHECK(cv::norm(r.labels, r2.labels, cv::NORM_INF) == 0.0);
}
