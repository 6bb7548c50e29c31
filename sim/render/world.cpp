#include "sim/render/world.hpp"

#include <cmath>
#include <stdexcept>
#include <unordered_set>

#include "sim/render/procedural_texture.hpp"
#include "sim/render/random.hpp"

namespace dynavins::sim {

World::World(const TextureDensity& density) : density_(density) {
  objects_.push_back(WorldObject{kStaticObject, "static", PoseFunction{}, {}});
}

int World::add_object(const std::string& name, PoseFunction pose) {
  if (objects_.size() >= static_cast<size_t>(kMaxObjects)) {
    throw std::length_error("World: at most 255 moving objects (labels are 8-bit)");
  }
  const int id = static_cast<int>(objects_.size());
  objects_.push_back(WorldObject{id, name.empty() ? "object" + std::to_string(id) : name, std::move(pose), {}});
  return id;
}

void World::add_quad(int object_id, Quad quad) {
  if (object_id < 0 || object_id >= static_cast<int>(objects_.size())) {
    throw std::out_of_range("World::add_quad: unknown object id");
  }
  if (!quad.texture) throw std::invalid_argument("World::add_quad: quad without texture");
  objects_[static_cast<size_t>(object_id)].quads.push_back(std::move(quad));
}

void World::add_ground(const GroundSpec& spec) {
  const double texel = density_.ground_m;
  for (double y = spec.y_min; y < spec.y_max - 1e-9; y += spec.tile_m) {
    for (double x = spec.x_min; x < spec.x_max - 1e-9; x += spec.tile_m) {
      const double w = std::min(spec.tile_m, spec.x_max - x);
      const double h = std::min(spec.tile_m, spec.y_max - y);
      Quad q;
      q.origin = Eigen::Vector3d(x, y, spec.z);
      q.edge_u = Eigen::Vector3d(w, 0.0, 0.0);
      q.edge_v = Eigen::Vector3d(0.0, h, 0.0);
      q.texture = std::make_shared<const MipTexture>(paint_ground(spec.layout, x, y, w, h, texel));
      add_quad(kStaticObject, std::move(q));
    }
  }
}

void World::add_box(const Eigen::Vector3d& size, const Eigen::Isometry3d& pose, uint64_t seed, int object_id,
                    BoxStyle style) {
  const double L = size.x(), W = size.y(), H = size.z();
  const bool vehicle = style == BoxStyle::Car || style == BoxStyle::Truck;
  const double texel = vehicle ? density_.vehicle_m : density_.building_m;
  // Face kinds: front (+x), back (-x), sides (+y, -y), top.
  SurfaceKind front = SurfaceKind::Facade, back = SurfaceKind::Facade, side = SurfaceKind::Facade,
              top = SurfaceKind::Roof;
  if (style == BoxStyle::Wall) front = back = side = SurfaceKind::Wall;
  if (style == BoxStyle::Car) {
    front = SurfaceKind::CarFront, back = SurfaceKind::CarBack, side = SurfaceKind::CarSide, top = SurfaceKind::CarTop;
  }
  if (style == BoxStyle::Truck) {
    front = SurfaceKind::TruckFront, back = SurfaceKind::TruckBack, side = SurfaceKind::TruckSide,
    top = SurfaceKind::TruckTop;
  }
  // Buildings and walls get a different texture per face; a vehicle's faces share its seed (colour).
  auto face_seed = [&](int face) { return vehicle ? seed : hash3(seed, face, 0xFACE); };
  struct Face {
    Eigen::Vector3d origin, eu, ev;
    SurfaceKind kind;
    bool front_at_u0;
    int id;
  };
  const Eigen::Vector3d X = Eigen::Vector3d::UnitX(), Y = Eigen::Vector3d::UnitY(), Z = Eigen::Vector3d::UnitZ();
  // eu = up x normal keeps textures upright and unmirrored seen from outside.
  const Face faces[] = {
      {Eigen::Vector3d(L / 2, -W / 2, 0), W * Y, H * Z, front, true, 0},
      {Eigen::Vector3d(-L / 2, W / 2, 0), -W * Y, H * Z, back, true, 1},
      {Eigen::Vector3d(L / 2, W / 2, 0), -L * X, H * Z, side, true, 2},
      {Eigen::Vector3d(-L / 2, -W / 2, 0), L * X, H * Z, side, false, 3},
      {Eigen::Vector3d(-L / 2, -W / 2, H), L * X, W * Y, top, true, 4},
  };
  for (const Face& f : faces) {
    SurfaceSpec spec;
    spec.kind = f.kind;
    spec.width_m = f.eu.norm();
    spec.height_m = f.ev.norm();
    spec.texel_m = texel;
    spec.seed = face_seed(f.id);
    spec.front_at_u0 = f.front_at_u0;
    Quad q;
    q.origin = pose * f.origin;
    q.edge_u = pose.linear() * f.eu;
    q.edge_v = pose.linear() * f.ev;
    q.texture = make_surface_texture(spec);
    add_quad(object_id, std::move(q));
  }
}

void World::add_wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double height, uint64_t seed,
                     double base_z) {
  const Eigen::Vector2d d = b - a;
  const Eigen::Vector2d c = 0.5 * (a + b);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(std::atan2(d.y(), d.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(c.x(), c.y(), base_z);
  add_box(Eigen::Vector3d(d.norm(), 0.25, height), pose, seed, kStaticObject, BoxStyle::Wall);
}

void World::add_building(const Eigen::Vector2d& centre, double yaw, double length, double depth, double height,
                         uint64_t seed, double base_z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(centre.x(), centre.y(), base_z);
  add_box(Eigen::Vector3d(length, depth, height), pose, seed, kStaticObject, BoxStyle::Building);
}

int World::add_moving_box(const Eigen::Vector3d& size, PoseFunction pose, uint64_t seed, BoxStyle style,
                          const std::string& name) {
  const int id = add_object(name, std::move(pose));
  add_box(size, Eigen::Isometry3d::Identity(), seed, id, style);
  return id;
}

int World::add_car(PoseFunction pose, uint64_t seed) {
  return add_moving_box(Eigen::Vector3d(4.5, 1.8, 1.5), std::move(pose), seed, BoxStyle::Car, "car");
}

int World::add_truck(PoseFunction pose, uint64_t seed) {
  return add_moving_box(Eigen::Vector3d(10.0, 2.5, 3.5), std::move(pose), seed, BoxStyle::Truck, "truck");
}

size_t World::num_quads() const {
  size_t n = 0;
  for (const auto& o : objects_) n += o.quads.size();
  return n;
}

size_t World::texture_bytes() const {
  std::unordered_set<const MipTexture*> seen;
  size_t bytes = 0;
  for (const auto& o : objects_) {
    for (const auto& q : o.quads) {
      if (seen.insert(q.texture.get()).second) bytes += q.texture->bytes();
    }
  }
  return bytes;
}

}  // namespace dynavins::sim
