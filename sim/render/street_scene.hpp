#pragma once
// A ready-made street for tests and examples: a straight avenue along world +x with a cross street,
// buildings and walls on both sides, parked cars, and moving vehicles (a truck driving ahead in the
// right lane, an oncoming car, a car crossing at the junction). Scenario code builds its own worlds
// with the World builders; this one only shows how.

#include <cstdint>

#include <Eigen/Geometry>

#include "sim/render/world.hpp"

namespace dynavins::sim {

struct StreetSceneOptions {
  uint64_t seed = 7;
  double x_min = -30.0;  ///< extent of the street along x [m]
  double x_max = 120.0;
  double ground_half_width = 30.0;  ///< ground extent either side of the street axis [m]
  bool moving_vehicles = true;
  double truck_start_x = 9.0;  ///< truck's centre x at t = 0 (it drives at truck_speed along +x)
  double truck_speed = 3.0;    ///< [m/s]
  TextureDensity density;
};

/// Lane centres and geometry of the scene: the avenue is 10 m wide (parking strips on both sides),
/// traffic drives on the right, i.e. at y = -kLaneOffset going +x.
struct StreetGeometry {
  static constexpr double kRoadWidth = 10.0;
  static constexpr double kLaneOffset = 1.75;
  static constexpr double kCrossStreetX = 60.0;
};

/// Builds the scene. Object ids of the moving vehicles are 1 (truck), 2 (oncoming car), 3 (crossing car).
World make_street_scene(const StreetSceneOptions& options = {});

/// Camera pose at (x, y, z) looking along +x turned by yaw (left positive) and pitch (up positive);
/// at zero angles camera z = world +x, camera x = world -y, camera y = world -z.
Eigen::Isometry3d street_camera_pose(double x, double y, double z, double yaw = 0.0, double pitch = 0.0);

}  // namespace dynavins::sim
