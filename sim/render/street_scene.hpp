#pragma once
// The street world of the scenarios, tests and examples: straight avenues along world +x (one by
// default) and cross streets along y, buildings and walls along both sides, parked cars, and optional
// moving vehicles (a truck driving ahead in the right lane, an oncoming car, a car crossing at the
// junction). Scenarios add their own moving objects with the World builders.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "sim/render/world.hpp"

namespace dynavins::sim {

/// Lane centres and geometry of the scene: each avenue is 10 m wide (parking strips on both sides),
/// traffic drives on the right, i.e. at y = avenue - kLaneOffset going +x.
struct StreetGeometry {
  static constexpr double kRoadWidth = 10.0;
  static constexpr double kLaneOffset = 1.75;
  static constexpr double kCrossStreetX = 60.0;
  static constexpr double kCrossStreetWidth = 8.0;
};

struct StreetSceneOptions {
  uint64_t seed = 7;
  double x_min = -30.0;  ///< extent of the avenues along x [m]
  double x_max = 120.0;
  double ground_half_width = 30.0;  ///< ground extent beyond the outermost avenues [m]
  /// Avenues along x, at these y [m]; buildings and parked cars line both sides of each.
  std::vector<double> avenue_y{0.0};
  /// Cross streets along y, at these x [m], over the whole ground; junctions left open. Between two
  /// avenues they are lined with buildings too (a city block), beyond the outermost ones open ground.
  std::vector<double> cross_street_x{StreetGeometry::kCrossStreetX};
  bool moving_vehicles = true;
  double truck_start_x = 9.0;  ///< truck's centre x at t = 0 (it drives at truck_speed along +x)
  double truck_speed = 3.0;    ///< [m/s]
  TextureDensity density;
};

/// Builds the scene. Object ids of the moving vehicles are 1 (truck), 2 (oncoming car), 3 (crossing car).
World make_street_scene(const StreetSceneOptions& options = {});

/// Camera pose at (x, y, z) looking along +x turned by yaw (left positive) and pitch (up positive);
/// at zero angles camera z = world +x, camera x = world -y, camera y = world -z.
Eigen::Isometry3d street_camera_pose(double x, double y, double z, double yaw = 0.0, double pitch = 0.0);

}  // namespace dynavins::sim
