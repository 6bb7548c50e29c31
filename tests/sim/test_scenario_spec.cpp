#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>

#include "sim/scenario/scenario.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins::sim;
namespace fs = std::filesystem;

namespace {
std::string write_yaml(const std::string& name, const std::string& body) {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_scenario";
  fs::create_directories(dir);
  std::ofstream(dir / name) << "%YAML:1.0\n---\n" << body;
  return (dir / name).string();
}
}  // namespace

TEST_CASE("load_scenario reads every part of a scenario", "[scenario]") {
  const auto path = write_yaml("ok.yaml",
                               "name: t\nseed: 3\nduration: 12.5\nphotometric: night\n"
                               "world: { x_min: -10, x_max: 90, seed: 5, avenues: [0, 60], cross_streets: [40] }\n"
                               "motion: { profile: car, cruise_speed: 4, waypoints: [0, 0, 1.5, 50, 0, 1.5] }\n"
                               "objects:\n"
                               "  - { kind: truck, motion: lane, x0: 30, y: -1.75, speed: 3 }\n"
                               "  - { kind: car, motion: cross_ahead, t: 5, distance: 6, speed: -4 }\n"
                               "  - { kind: truck, motion: follow, distance: 7 }\n"
                               "  - { kind: board, motion: relocate, poses: [0, 10, 4, 90, 20, 40, 4, 90] }\n");
  const ScenarioSpec s = load_scenario(path);
  CHECK(s.name == "t");
  CHECK(s.seed == 3);
  CHECK(s.duration == 12.5);
  CHECK(s.photometric == "night");
  CHECK(s.rig == "euroc");  // the default
  CHECK(s.world_x_max == 90);
  CHECK(s.avenue_y == std::vector<double>{0, 60});
  CHECK(s.cross_street_x == std::vector<double>{40});
  CHECK(s.profile == "car");
  REQUIRE(s.waypoints.size() == 2);
  CHECK(s.waypoints[1] == Eigen::Vector3d(50, 0, 1.5));
  REQUIRE(s.objects.size() == 4);
  CHECK(s.objects[0].motion == ObjectMotion::Lane);
  CHECK(s.objects[1].speed == -4);
  CHECK(s.objects[2].motion == ObjectMotion::Follow);
  REQUIRE(s.objects[3].poses.size() == 2);
  CHECK(s.objects[3].poses[1][1] == 40);
}

TEST_CASE("load_scenario reads recorded motion, its path relative to the scenario file", "[scenario]") {
  const auto path = write_yaml("tum.yaml",
                               "name: t\nduration: 30\n"
                               "motion: { tum: traj/V1.txt.gz, tum_start: 4, placement: [20, -1, 0.5, 90],"
                               " body_axes: euroc }\n");
  const ScenarioSpec s = load_scenario(path);
  CHECK(s.tum_file == (fs::path(path).parent_path() / "traj/V1.txt.gz").string());
  CHECK(s.tum_start == 4);
  CHECK(s.tum_placement == Eigen::Vector4d(20, -1, 0.5, 90));
  CHECK(s.tum_body_axes == "euroc");
  CHECK(s.waypoints.empty());
  const auto abs = write_yaml("tum_abs.yaml", "name: t\nmotion: { tum: /data/x.txt }\n");
  CHECK(load_scenario(abs).tum_file == "/data/x.txt");
  CHECK(load_scenario(abs).tum_body_axes == "sim");

  auto p = write_yaml("tum_mix.yaml", "name: t\nmotion: { tum: x.txt, waypoints: [0, 0, 1, 5, 0, 1] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("motion.waypoints: unknown key"));
  p = write_yaml("tum_pl.yaml", "name: t\nmotion: { tum: x.txt, placement: [1, 2, 3] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("placement"));
  p = write_yaml("tum_axes.yaml", "name: t\nmotion: { tum: x.txt, body_axes: ned }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("'ned' is not one of"));
  p = write_yaml("tum_start.yaml", "name: t\nmotion: { tum: x.txt, tum_start: -1 }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("motion.tum_start: must be >= 0"));
}

TEST_CASE("load_scenario: a wrong, unknown or missing key is an error naming key and file", "[scenario]") {
  const std::string motion = "motion: { waypoints: [0, 0, 1.5, 50, 0, 1.5] }\n";
  auto p = write_yaml("typo.yaml", "name: t\nsede: 3\n" + motion);
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains(p) && Catch::Contains("sede: unknown key"));
  p = write_yaml("avenues.yaml", "name: t\nworld: { avenues: [0, 30] }\n" + motion);
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("world.avenues: must be at least 50 m apart"));
  p = write_yaml("nomotion.yaml", "name: t\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("motion: missing"));
  p = write_yaml("kind.yaml", "name: t\n" + motion + "objects:\n  - { kind: bus, motion: lane, x0: 0, y: 0, speed: 1 }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("kind: 'bus' is not one of"));
  p = write_yaml("lane.yaml", "name: t\n" + motion + "objects:\n  - { kind: car, motion: lane, x0: 0, y: 0 }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("speed: missing"));
  p = write_yaml("wp.yaml", "name: t\nmotion: { waypoints: [0, 0, 1.5, 50, 0] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("groups of 3"));
  p = write_yaml("rig.yaml", "name: t\nrig: kinect\n" + motion);
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("rig: 'kinect' is not one of"));
  CHECK_THROWS_WITH(load_scenario("/nonexistent/s.yaml"), Catch::Contains("/nonexistent/s.yaml"));
}

TEST_CASE("load_scenario: rig picks the stereo rig the scene is rendered with", "[scenario]") {
  const auto path = write_yaml("viode.yaml", "name: t\nrig: viode\nduration: 1\n"
                                             "motion: { waypoints: [0, -1.5, 1.6, 30, -1.5, 1.6] }\n");
  const ScenarioSpec spec = load_scenario(path);
  CHECK(spec.rig == "viode");
  const auto s = build_scenario(spec);
  CHECK(s->rig.camera.fx == 376.0);
  CHECK(s->rig.camera.k1 == 0.0);
  const Eigen::Isometry3d c0_c1 = s->rig.T_body_cam0.inverse() * s->rig.T_body_cam1;
  CHECK((c0_c1.translation() - Eigen::Vector3d(0.05, 0, 0)).norm() < 1e-12);
  const auto config = vins_config(*s);  // what `sim --euroc` hands the estimator
  CHECK(config.cam0.fx == 376.0);
  CHECK(((config.body_T_cam0.inverse() * config.body_T_cam1).translation() - Eigen::Vector3d(0.05, 0, 0)).norm() < 1e-12);
  CHECK(StereoRig::preset("euroc").baseline == 0.11);
  CHECK_THROWS(StereoRig::preset("kinect"));
}

TEST_CASE("load_scenario: motion.dwell stops the path at a waypoint for that long", "[scenario]") {
  const std::string motion = "motion: { profile: car, cruise_speed: 3, waypoints: [0, 0, 1.5, 12, 0, 1.5, 24, 0, 1.5]";
  const auto path = write_yaml("dwell.yaml", "name: t\n" + motion + ", dwell: [1, 20] }\n");
  const ScenarioSpec s = load_scenario(path);
  REQUIRE(s.dwell.size() == 3);
  CHECK(s.dwell[1] == 20.0);
  CHECK(s.dwell[0] == 0.0);
  const ScenarioSpec plain = load_scenario(write_yaml("nodwell.yaml", "name: t\n" + motion + " }\n"));
  const auto with = build_body_trajectory(s), without = build_body_trajectory(plain);
  // The stop adds its 20 s (and the braking and starting a corner stop costs).
  CHECK(with->duration() > without->duration() + 20.0);
  // Somewhere in the middle the body stands at the second waypoint.
  const double mid = with->t_min() + 0.5 * with->duration();
  CHECK(with->velocity(mid).norm() < 1e-3);
  CHECK((with->position(mid) - Eigen::Vector3d(12, 0, 1.5)).norm() < 0.5);

  auto p = write_yaml("dwell_idx.yaml", "name: t\n" + motion + ", dwell: [3, 5] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("motion.dwell: waypoint index"));
  p = write_yaml("dwell_len.yaml", "name: t\n" + motion + ", dwell: [1, -5] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("motion.dwell: seconds must be"));
  p = write_yaml("dwell_odd.yaml", "name: t\n" + motion + ", dwell: [1] }\n");
  CHECK_THROWS_WITH(load_scenario(p), Catch::Contains("dwell"));
}
