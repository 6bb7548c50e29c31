// A short scenario rendered as a sensor stream, checked against its own ground truth.
#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "sim/scenario/scenario.hpp"
#include "sim/render/camera_rays.hpp"

using namespace dynavins;
using namespace dynavins::sim;
namespace fs = std::filesystem;

namespace {

/// 3 s along the avenue with a truck crossing 6 m ahead at t = 1.5 s and a car driving ahead.
std::shared_ptr<const Scenario> short_scene(const std::string& rig = "euroc") {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_scenario";
  fs::create_directories(dir);
  const fs::path path = dir / "short.yaml";
  std::ofstream(path) << "%YAML:1.0\n---\nname: short\nseed: 2\nduration: 3\n"
                         "world: { x_min: -20, x_max: 60 }\n"
                         "motion: { profile: drone, waypoints: [0, -1.5, 1.6, 30, -1.5, 1.6] }\n"
                         "objects:\n"
                         "  - { kind: truck, motion: cross_ahead, t: 2.0, distance: 7, speed: 6 }\n"
                         "  - { kind: car, motion: lane, x0: 15, y: -1.75, speed: 1 }\n";
  ScenarioSpec spec = load_scenario(path.string());
  spec.rig = rig;
  return build_scenario(spec);
}

}  // namespace

TEST_CASE("ScenarioSource: events in time order, 20 Hz frames, 200 Hz IMU and ground truth", "[scenario]") {
  ScenarioSource src(short_scene());
  SensorEvent e;
  int64_t last = INT64_MIN, first_frame = -1, last_frame = -1;
  int frames = 0, imu = 0, gt = 0;
  while (src.next(e)) {
    REQUIRE(event_time_ns(e) >= last);
    last = event_time_ns(e);
    if (const auto* f = std::get_if<StereoFrame>(&e)) {
      if (first_frame < 0) first_frame = f->t_ns;
      last_frame = f->t_ns;
      REQUIRE(f->left.type() == CV_8UC1);
      REQUIRE(f->right.size() == f->left.size());
      REQUIRE(f->labels.size() == f->left.size());
      ++frames;
    }
    imu += std::holds_alternative<ImuSample>(e);
    gt += std::holds_alternative<GroundTruthState>(e);
  }
  CHECK(frames == 61);
  CHECK(static_cast<double>(last_frame - first_frame) / 1e9 == Approx(3.0));
  CHECK(imu == 601);
  CHECK(gt == imu);
  CHECK(src.progress() == 1.0);
}

TEST_CASE("ScenarioSource: labels mark the moving objects where the geometry puts them", "[scenario]") {
  const auto scenario = short_scene();
  ScenarioSource src(scenario);
  SensorEvent e;
  int checked = 0, moving_frames = 0;
  while (src.next(e)) {
    const auto* f = std::get_if<StereoFrame>(&e);
    if (!f) continue;
    const double t = static_cast<double>(f->t_ns - scenario->epoch_ns) / 1e9;
    const Eigen::Isometry3d T_cam_world = (scenario->body->pose(t) * scenario->rig.T_body_cam0).inverse();
    // The centre of each moving object's side facing up at mid height: where it projects in view
    // and nothing is nearer, the label there is that object's.
    for (std::size_t k = 1; k < scenario->world->objects().size(); ++k) {
      const auto& obj = scenario->world->objects()[k];
      const Eigen::Vector3d p_cam = T_cam_world * (obj.pose_at(t) * Eigen::Vector3d(0, 0, 1.0));
      if (p_cam.z() < 1.0) continue;
      const Eigen::Vector2d px = project_point(scenario->rig.camera, p_cam);
      const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
      if (u < 2 || v < 2 || u >= f->labels.cols - 2 || v >= f->labels.rows - 2) continue;
      const float depth = src.last_left().depth.at<float>(v, u);
      if (depth < p_cam.z() - 2.5) continue;  // occluded by something nearer than the object's body
      CHECK(static_cast<std::size_t>(f->labels.at<uint8_t>(v, u)) == k);
      ++checked;
    }
    moving_frames += cv::countNonZero(f->labels) > 0;
  }
  CHECK(checked > 20);
  CHECK(moving_frames > 30);
}

TEST_CASE("ScenarioSource: static pixels' depth is consistent between the stereo views", "[scenario]") {
  const std::string rig_name = GENERATE(as<std::string>{}, "euroc", "viode");
  INFO("rig " << rig_name);
  ScenarioSource src(short_scene(rig_name));
  SensorEvent e;
  while (src.next(e) && !std::holds_alternative<StereoFrame>(e)) {
  }
  const auto& rig = src.scenario().rig;
  const RenderedView& L = src.last_left();
  const RenderedView& R = src.last_right();
  const Eigen::Isometry3d T_c1_c0 = rig.T_body_cam1.inverse() * rig.T_body_cam0;
  int agree = 0, tested = 0;
  for (int v = 20; v < L.depth.rows - 20; v += 23) {
    for (int u = 20; u < L.depth.cols - 20; u += 29) {
      const float d = L.depth.at<float>(v, u);
      if (!std::isfinite(d) || L.labels.at<uint8_t>(v, u) != 0) continue;
      Eigen::Vector2d xn;
      REQUIRE(undistort_pixel(rig.camera, Eigen::Vector2d(u, v), &xn));
      const Eigen::Vector3d p1 = T_c1_c0 * (Eigen::Vector3d(xn.x(), xn.y(), 1.0) * d);
      const Eigen::Vector2d q = project_point(rig.camera, p1);
      const int ur = static_cast<int>(std::lround(q.x())), vr = static_cast<int>(std::lround(q.y()));
      if (ur < 0 || vr < 0 || ur >= R.depth.cols || vr >= R.depth.rows) continue;
      ++tested;
      agree += std::abs(R.depth.at<float>(vr, ur) - static_cast<float>(p1.z())) < 0.02f * static_cast<float>(p1.z());
    }
  }
  CHECK(tested > 100);
  CHECK(agree >= 0.95 * tested);  // the rest: pixels on an occlusion edge in one of the views
}
