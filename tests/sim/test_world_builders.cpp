// World: objects, quads and the ground / box / wall / vehicle builders.

#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>

#include "sim/render/world.hpp"

using namespace dynavins::sim;

namespace {

Eigen::Vector3d quad_centre(const Quad& q) { return q.origin + 0.5 * (q.edge_u + q.edge_v); }

TextureDensity coarse() {  // keep the tests' textures small
  TextureDensity d;
  d.ground_m = 0.1;
  d.building_m = 0.1;
  d.vehicle_m = 0.05;
  return d;
}

}  // namespace

TEST_CASE("World: object 0 is static, moving objects get ids 1, 2, ... and their pose", "[world]") {
  World w(coarse());
  REQUIRE(w.objects().size() == 1);
  CHECK(w.object(0).id == 0);
  CHECK(w.object(0).pose_at(12.0).isApprox(Eigen::Isometry3d::Identity()));
  auto path = [](double t) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(2.0 * t, 0.0, 0.0);
    return T;
  };
  CHECK(w.add_car(path, 1) == 1);
  CHECK(w.add_truck(path, 2) == 2);
  CHECK(w.object(2).pose_at(3.0).translation().x() == Approx(6.0));
  CHECK(w.object(1).quads.size() == 5);
  CHECK_THROWS_AS(w.add_quad(7, Quad{}), std::out_of_range);
  CHECK_THROWS_AS(w.add_quad(0, Quad{}), std::invalid_argument);  // no texture
}

TEST_CASE("World: labels are 8-bit, so at most 255 moving objects", "[world]") {
  World w(coarse());
  for (int k = 1; k < World::kMaxObjects; ++k) REQUIRE(w.add_object("o", PoseFunction{}) == k);
  CHECK_THROWS_AS(w.add_object("one too many", PoseFunction{}), std::length_error);
}

TEST_CASE("World: add_box makes five outward-facing faces on the box surface", "[world]") {
  World w(coarse());
  const Eigen::Vector3d size(4.0, 2.0, 3.0);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(10.0, -3.0, 0.5);
  w.add_box(size, pose, 3, World::kStaticObject, BoxStyle::Building);
  const auto& quads = w.object(0).quads;
  REQUIRE(quads.size() == 5);
  const Eigen::Vector3d centre = pose * Eigen::Vector3d(0, 0, 0.5 * size.z());
  double area = 0.0;
  for (const Quad& q : quads) {
    CHECK(q.normal().dot(quad_centre(q) - centre) > 0.0);       // outward
    CHECK(std::abs(q.edge_u.dot(q.edge_v)) < 1e-9);             // rectangles
    area += q.edge_u.cross(q.edge_v).norm();
    // Every corner lies on the box: in box coordinates, on its boundary.
    const Eigen::Vector3d corners[] = {q.origin, q.origin + q.edge_u, q.origin + q.edge_v, q.origin + q.edge_u + q.edge_v};
    for (const Eigen::Vector3d& c : corners) {
      const Eigen::Vector3d b = pose.inverse() * c;
      CHECK(std::abs(b.x()) <= 0.5 * size.x() + 1e-9);
      CHECK(std::abs(b.y()) <= 0.5 * size.y() + 1e-9);
      CHECK(b.z() >= -1e-9);
      CHECK(b.z() <= size.z() + 1e-9);
    }
    // Side faces are upright: edge_v points up, so textures are not upside down.
    if (std::abs(q.normal().z()) < 0.5) CHECK(q.edge_v.normalized().z() == Approx(1.0));
  }
  CHECK(area == Approx(2 * (4.0 * 3.0 + 2.0 * 3.0) + 4.0 * 2.0));
}

TEST_CASE("World: texture resolution follows the texel density", "[world]") {
  TextureDensity d;
  d.vehicle_m = 0.01;
  World w(d);
  const int id = w.add_car(PoseFunction{}, 4);
  bool found_side = false;
  for (const Quad& q : w.object(id).quads) {
    if (std::abs(q.edge_u.norm() - 4.5) < 1e-9 && std::abs(q.edge_v.norm() - 1.5) < 1e-9) {
      CHECK(q.texture->width() == 450);
      CHECK(q.texture->height() == 150);
      found_side = true;
    }
  }
  CHECK(found_side);
}

TEST_CASE("World: the ground tiles cover the extent once, facing up", "[world]") {
  World w(coarse());
  GroundSpec g;
  g.x_min = -10;
  g.x_max = 25;  // not a multiple of the tile
  g.y_min = -7;
  g.y_max = 7;
  g.tile_m = 8;
  w.add_ground(g);
  const auto& quads = w.object(0).quads;
  CHECK(quads.size() == 5 * 2);
  double area = 0.0;
  for (const Quad& q : quads) {
    CHECK(q.normal().z() == Approx(1.0));
    CHECK(q.origin.z() == 0.0);
    area += q.edge_u.cross(q.edge_v).norm();
    CHECK(q.origin.x() >= g.x_min);
    CHECK(q.origin.x() + q.edge_u.x() <= g.x_max + 1e-9);
  }
  CHECK(area == Approx(35.0 * 14.0));
  CHECK(w.texture_bytes() > 0);
}

TEST_CASE("World: a wall runs from a to b", "[world]") {
  World w(coarse());
  w.add_wall({0.0, 0.0}, {6.0, 8.0}, 2.0, 5);
  const auto& quads = w.object(0).quads;
  REQUIRE(quads.size() == 5);
  double longest = 0.0;
  for (const Quad& q : quads) longest = std::max(longest, q.edge_u.norm());
  CHECK(longest == Approx(10.0));
  // Its long faces are parallel to a->b.
  int parallel = 0;
  for (const Quad& q : quads) {
    if (std::abs(q.edge_u.normalized().dot(Eigen::Vector3d(0.6, 0.8, 0.0))) > 0.999 && q.normal().z() == Approx(0.0).margin(1e-9)) ++parallel;
  }
  CHECK(parallel == 2);
}

TEST_CASE("World: texture memory counts shared textures once", "[world]") {
  World w(coarse());
  w.add_box(Eigen::Vector3d(3, 3, 3), Eigen::Isometry3d::Identity(), 1);
  const size_t one = w.texture_bytes();
  Quad copy = w.object(0).quads.front();
  copy.origin.x() += 10.0;
  w.add_quad(0, copy);
  CHECK(w.texture_bytes() == one);
  CHECK(w.num_quads() == 6);
}
