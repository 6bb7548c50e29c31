#include "sim/render/street_scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

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

/// Lines one side of a straight street with buildings, closing some gaps with walls. The street runs
/// along `along` (a unit axis) from s_min to s_max; building fronts stand `front` from its centre line
/// on `side` (+1: left of `along`); [lo, hi] intervals of `keep_clear` (in s) are left open.
void line_street(World& world, Rng& rng, const Eigen::Vector2d& origin, const Eigen::Vector2d& along, int side,
                 double s_min, double s_max, double front, const std::vector<std::pair<double, double>>& keep_clear) {
  const Eigen::Vector2d left(-along.y(), along.x());
  const double yaw = std::atan2(along.y(), along.x()) + (side > 0 ? kPi : 0.0);
  double s = s_min;
  while (s < s_max) {
    const double len = rng.uniform(8.0, 24.0);
    const double gap = rng.chance(0.35) ? rng.uniform(2.0, 6.0) : 0.0;
    double s0 = s, s1 = std::min(s + len, s_max);
    bool skipped = false;
    for (const auto& [lo, hi] : keep_clear) {  // sorted: the first one reached is the one to stop at
      if (s1 > lo && s0 < hi) {
        if (s0 < lo) {
          s1 = lo;
        } else {
          s = hi;
          skipped = true;
        }
        break;
      }
    }
    if (skipped) continue;
    const double depth = rng.uniform(8.0, 14.0);
    const double height = rng.uniform(6.0, 22.0);
    const Eigen::Vector2d centre = origin + 0.5 * (s0 + s1) * along + side * (front + 0.5 * depth) * left;
    world.add_building(centre, yaw, s1 - s0, depth, height, rng.next());
    if (gap > 0.0) {
      const Eigen::Vector2d base = origin + side * (front + 0.4) * left;
      world.add_wall(base + s1 * along, base + (s1 + gap) * along, rng.uniform(1.8, 2.6), rng.next());
    }
    s = s1 + gap;
  }
}

}  // namespace

World make_street_scene(const StreetSceneOptions& o) {
  if (o.avenue_y.empty()) throw std::invalid_argument("make_street_scene: needs at least one avenue");
  World world(o.density);
  Rng rng(o.seed);
  std::vector<double> avenues = o.avenue_y, crosses = o.cross_street_x;
  std::sort(avenues.begin(), avenues.end());
  std::sort(crosses.begin(), crosses.end());
  const double half_road = 0.5 * StreetGeometry::kRoadWidth;
  const double y_min = avenues.front() - o.ground_half_width, y_max = avenues.back() + o.ground_half_width;

  GroundSpec ground;
  ground.x_min = o.x_min;
  ground.x_max = o.x_max;
  ground.y_min = y_min;
  ground.y_max = y_max;
  ground.layout.seed = mix64(o.seed + 1);
  for (double y : avenues)
    ground.layout.roads.push_back(Road{Eigen::Vector2d(o.x_min - 10.0, y), Eigen::Vector2d(o.x_max + 10.0, y),
                                       StreetGeometry::kRoadWidth, true});
  for (double x : crosses)
    ground.layout.roads.push_back(Road{Eigen::Vector2d(x, y_min - 10.0), Eigen::Vector2d(x, y_max + 10.0),
                                       StreetGeometry::kCrossStreetWidth, true});
  world.add_ground(ground);

  // Buildings along both sides of each avenue, fronts behind the sidewalk; gaps closed by walls; the
  // junctions left open.
  const double front = half_road + ground.layout.curb_m + ground.layout.sidewalk_m + 0.3;
  const double cross_half =
      0.5 * StreetGeometry::kCrossStreetWidth + ground.layout.curb_m + ground.layout.sidewalk_m + 0.3;
  std::vector<std::pair<double, double>> junctions;
  for (double x : crosses) junctions.emplace_back(x - cross_half, x + cross_half);
  for (double y : avenues)
    for (int side : {-1, 1})
      line_street(world, rng, Eigen::Vector2d(0.0, y), Eigen::Vector2d::UnitX(), side, o.x_min, o.x_max, front,
                  junctions);

  // Parked cars on the avenues' parking strips (static world), with irregular spacing.
  for (double y : avenues) {
    for (int side : {-1, 1}) {
      for (double x = o.x_min + rng.uniform(0.0, 6.0); x < o.x_max - 3.0; x += rng.uniform(5.5, 14.0)) {
        if (std::any_of(crosses.begin(), crosses.end(), [x](double cx) { return std::abs(x - cx) < 9.0; })) continue;
        Eigen::Isometry3d T = planar_pose(x, y + side * (half_road - 1.05), side > 0 ? kPi : 0.0);
        world.add_box(Eigen::Vector3d(4.5, 1.8, 1.5), T, rng.next(), World::kStaticObject, BoxStyle::Car);
      }
    }
  }

  // Cross streets between two avenues are lined too (a city block), clear of the avenues' buildings
  // (at most 14 m deep); beyond the outermost avenues they run through open ground.
  constexpr double kMaxBuildingDepth = 14.0;
  const double clear = front + kMaxBuildingDepth + 1.0;
  for (size_t k = 0; k + 1 < avenues.size(); ++k) {
    const double s0 = avenues[k] + clear, s1 = avenues[k + 1] - clear;
    if (s1 - s0 < 8.0) continue;
    for (double x : crosses)
      for (int side : {-1, 1})
        line_street(world, rng, Eigen::Vector2d(x, 0.0), Eigen::Vector2d::UnitY(), side, s0, s1, cross_half, {});
  }

  if (o.moving_vehicles) {
    const double cx = StreetGeometry::kCrossStreetX;
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
