#include "sim/render/street_scene.hpp"

#include <algorithm>
#include <cmath>

#include "sim/render/random.hpp"

namespace dynavins::sim {
namespace {

constexpr double kPi = 3.141592653589793;

Eigen::Isometry3d planar_pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

}  // namespace

World make_street_scene(const StreetSceneOptions& o) {
  World world(o.density);
  Rng rng(o.seed);
  const double cx = StreetGeometry::kCrossStreetX;
  const double half_road = 0.5 * StreetGeometry::kRoadWidth;

  GroundSpec ground;
  ground.x_min = o.x_min;
  ground.x_max = o.x_max;
  ground.y_min = -o.ground_half_width;
  ground.y_max = o.ground_half_width;
  ground.layout.seed = mix64(o.seed + 1);
  ground.layout.roads.push_back(Road{Eigen::Vector2d(o.x_min - 10.0, 0.0), Eigen::Vector2d(o.x_max + 10.0, 0.0),
                                     StreetGeometry::kRoadWidth, true});
  ground.layout.roads.push_back(Road{Eigen::Vector2d(cx, -o.ground_half_width - 10.0),
                                     Eigen::Vector2d(cx, o.ground_half_width + 10.0), 8.0, true});
  world.add_ground(ground);

  // Buildings along both sides, fronts behind the sidewalk; gaps closed by walls; the junction left open.
  const double front = half_road + ground.layout.curb_m + ground.layout.sidewalk_m + 0.3;
  const double cross_half = 4.0 + ground.layout.curb_m + ground.layout.sidewalk_m + 0.3;
  for (int side : {-1, 1}) {
    double x = o.x_min;
    while (x < o.x_max) {
      const double len = rng.uniform(8.0, 24.0);
      const double gap = rng.chance(0.35) ? rng.uniform(2.0, 6.0) : 0.0;
      double x0 = x, x1 = std::min(x + len, o.x_max);
      if (x1 > cx - cross_half && x0 < cx + cross_half) {  // keep the junction free
        if (x0 < cx - cross_half) {
          x1 = cx - cross_half;
        } else {
          x = cx + cross_half;
          continue;
        }
      }
      const double depth = rng.uniform(8.0, 14.0);
      const double height = rng.uniform(6.0, 22.0);
      const double yc = side * (front + 0.5 * depth);
      world.add_building(Eigen::Vector2d(0.5 * (x0 + x1), yc), side > 0 ? kPi : 0.0, x1 - x0, depth, height,
                         rng.next());
      if (gap > 0.0) {
        world.add_wall(Eigen::Vector2d(x1, side * (front + 0.4)), Eigen::Vector2d(x1 + gap, side * (front + 0.4)),
                       rng.uniform(1.8, 2.6), rng.next());
      }
      x = x1 + gap;
    }
  }

  // Parked cars on the parking strips (static world), with irregular spacing.
  for (int side : {-1, 1}) {
    for (double x = o.x_min + rng.uniform(0.0, 6.0); x < o.x_max - 3.0; x += rng.uniform(5.5, 14.0)) {
      if (std::abs(x - cx) < 9.0) continue;
      Eigen::Isometry3d T = planar_pose(x, side * (half_road - 1.05), side > 0 ? kPi : 0.0);
      world.add_box(Eigen::Vector3d(4.5, 1.8, 1.5), T, rng.next(), World::kStaticObject, BoxStyle::Car);
    }
  }

  if (o.moving_vehicles) {
    const double x0 = o.truck_start_x, v = o.truck_speed;
    const double lane = StreetGeometry::kLaneOffset;
    world.add_truck([x0, v, lane](double t) { return planar_pose(x0 + v * t, -lane, 0.0); }, mix64(o.seed + 2));
    world.add_car([lane](double t) { return planar_pose(70.0 - 6.0 * t, lane, kPi); }, mix64(o.seed + 3));
    world.add_car([cx](double t) { return planar_pose(cx + 2.0, -25.0 + 5.0 * t, 0.5 * kPi); },
                  mix64(o.seed + 4));
  }
  return world;
}

Eigen::Isometry3d street_camera_pose(double x, double y, double z, double yaw, double pitch) {
  // Camera axes in a forward-looking body frame (x fwd, y left, z up): z_c = x_b, x_c = -y_b, y_c = -z_b.
  Eigen::Matrix3d R_body_cam;
  R_body_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, -Eigen::Vector3d::UnitY()))
                   .toRotationMatrix() *
               R_body_cam;
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

}  // namespace dynavins::sim
