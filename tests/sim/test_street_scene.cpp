// make_street_scene: avenues, cross streets and the buildings along them.

#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#include "sim/render/street_scene.hpp"

using namespace dynavins::sim;

namespace {

StreetSceneOptions coarse_street() {  // keep the tests' textures small
  StreetSceneOptions o;
  o.density.ground_m = 0.2;
  o.density.building_m = 0.2;
  o.density.vehicle_m = 0.1;
  o.moving_vehicles = false;
  return o;
}

// Calls f on points 0.25 m apart over every quad of the static world that is more than 1.6 m above
// the ground (buildings and walls; the ground and the parked cars are lower).
void for_each_tall_point(const World& w, const std::function<void(const Eigen::Vector3d&)>& f) {
  for (const Quad& q : w.object(0).quads) {
    const int nu = 1 + static_cast<int>(q.edge_u.norm() / 0.25), nv = 1 + static_cast<int>(q.edge_v.norm() / 0.25);
    for (int i = 0; i <= nu; ++i)
      for (int j = 0; j <= nv; ++j) {
        const Eigen::Vector3d p = q.origin + (double(i) / nu) * q.edge_u + (double(j) / nv) * q.edge_v;
        if (p.z() > 1.6) f(p);
      }
  }
}

}  // namespace

TEST_CASE("Street scene: no building or wall stands on an avenue or a cross street", "[world][street]") {
  StreetSceneOptions o = coarse_street();
  o.x_min = -20;
  o.x_max = 160;
  o.avenue_y = {60.0, 0.0};  // any order
  o.cross_street_x = {120.0, 60.0};
  const World w = make_street_scene(o);
  // A wall closing the gap after an avenue's last building before a junction may reach into the cross
  // street's mouth, at most 6 m past the building line (every street scene has had this since the
  // first; the measured scenes depend on their worlds, so it stays), never into its lanes.
  const double wall_line = 0.5 * StreetGeometry::kRoadWidth + 0.2 + 3.0 + 0.3 + 0.4;  // curb, sidewalk, fronts
  int tall = 0, on_avenue = 0, on_cross_street = 0, in_lanes = 0;
  for_each_tall_point(w, [&](const Eigen::Vector3d& p) {
    ++tall;
    bool on_wall_line = false;
    for (double y : {0.0, 60.0}) {
      if (std::abs(p.y() - y) < 0.5 * StreetGeometry::kRoadWidth) ++on_avenue;
      if (std::abs(std::abs(p.y() - y) - wall_line) < 0.25) on_wall_line = true;  // 0.25 m thick
    }
    for (double x : {60.0, 120.0}) {
      if (std::abs(p.x() - x) < 0.5 * StreetGeometry::kCrossStreetWidth && !on_wall_line) ++on_cross_street;
      if (std::abs(p.x() - x) < 1.5) ++in_lanes;
    }
  });
  CHECK(tall > 1000);
  CHECK(on_avenue == 0);
  CHECK(on_cross_street == 0);
  CHECK(in_lanes == 0);
}

TEST_CASE("Street scene: cross streets are lined between two avenues, open beyond them", "[world][street]") {
  // Counts building points beside a cross street (within 25 m of its axis, off its carriageway) at
  // y in [y0, y1].
  const auto beside_cross_street = [](const World& w, double x, double y0, double y1) {
    int n = 0;
    for_each_tall_point(w, [&](const Eigen::Vector3d& p) {
      if (std::abs(p.x() - x) < 25.0 && p.y() > y0 && p.y() < y1) ++n;
    });
    return n;
  };
  StreetSceneOptions o = coarse_street();
  o.avenue_y = {0.0, 60.0};
  o.cross_street_x = {60.0};
  const World block = make_street_scene(o);
  CHECK(beside_cross_street(block, 60.0, 25.0, 35.0) > 100);  // mid-block, away from both avenues' buildings
  CHECK(beside_cross_street(block, 60.0, 85.0, 200.0) == 0);  // beyond the outer avenue's buildings

  const World one_avenue = make_street_scene(coarse_street());  // the default: one avenue at y = 0
  CHECK(beside_cross_street(one_avenue, 60.0, 25.0, 200.0) == 0);
  CHECK(beside_cross_street(one_avenue, 60.0, -200.0, -25.0) == 0);
}

TEST_CASE("Street scene: at least one avenue", "[world][street]") {
  StreetSceneOptions o = coarse_street();
  o.avenue_y.clear();
  CHECK_THROWS_AS(make_street_scene(o), std::invalid_argument);
}
