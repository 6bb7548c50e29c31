#pragma once
// The synthetic world: textured planar quads grouped into objects. Object 0 is the static world
// (ground, buildings, walls); objects k >= 1 move rigidly with a time-dependent pose T_world_object(t).
// World frame z up, metres. Box-shaped things have their frame at the centre of their bottom face,
// x forward (length), y left (width), z up (height).

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/render/ground_texture.hpp"
#include "sim/render/mip_texture.hpp"

namespace dynavins::sim {

/// Pose of an object in the world at time t [s]. Must be a pure function: render_stereo calls it from
/// two threads.
using PoseFunction = std::function<Eigen::Isometry3d(double t)>;

/// A textured parallelogram in its object's frame: texture (s, r) in [0, 1]^2 spans
/// origin + s * edge_u + r * edge_v. Its front side faces edge_u x edge_v.
struct Quad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();
  std::shared_ptr<const MipTexture> texture;
  bool two_sided = false;  ///< visible from behind too (else back-face culled)

  /// Unit normal of the front side.
  Eigen::Vector3d normal() const { return edge_u.cross(edge_v).normalized(); }
};

/// A rigid group of quads with one label. An empty pose function means the identity.
struct WorldObject {
  int id = 0;
  std::string name;
  PoseFunction pose;
  std::vector<Quad> quads;

  /// T_world_object at time t.
  Eigen::Isometry3d pose_at(double t) const { return pose ? pose(t) : Eigen::Isometry3d::Identity(); }
};

/// How box faces are textured.
enum class BoxStyle {
  Building,  ///< facades on the sides, a roof on top
  Wall,      ///< plain walls (concrete, posters, graffiti) on the sides
  Car,
  Truck,
};

/// Texel sizes [m] per kind of surface: texture detail against memory.
struct TextureDensity {
  double ground_m = 0.02;
  double building_m = 0.02;
  double vehicle_m = 0.01;
};

/// A tiled ground plane at height z over [x_min, x_max] x [y_min, y_max].
struct GroundSpec {
  double x_min = -50.0;
  double x_max = 50.0;
  double y_min = -50.0;
  double y_max = 50.0;
  double z = 0.0;
  double tile_m = 16.0;  ///< one texture per tile; keeps each texture modest
  GroundLayout layout;   ///< roads, sidewalks, seed
};

class World {
 public:
  static constexpr int kStaticObject = 0;
  static constexpr int kMaxObjects = 256;  ///< labels are 8-bit

  /// An empty world holding only the (empty) static object 0.
  explicit World(const TextureDensity& density = {});

  /// Adds an object moving with `pose`; returns its id (= its label, 1..255).
  int add_object(const std::string& name, PoseFunction pose);
  /// Adds a quad (in the object's frame) to object `object_id`.
  void add_quad(int object_id, Quad quad);

  /// Tiles the ground with painted road / sidewalk / verge textures (static object).
  void add_ground(const GroundSpec& spec);
  /// Adds a box of `size` (x length, y width, z height) whose bottom-face centre sits at `pose` in the
  /// frame of object `object_id`. Five faces (no bottom), textured per `style` from `texture_seed`.
  void add_box(const Eigen::Vector3d& size, const Eigen::Isometry3d& pose, uint64_t texture_seed,
               int object_id = kStaticObject, BoxStyle style = BoxStyle::Building);
  /// A free-standing wall on the ground from a to b (world x, y), `height` tall and 0.25 m thick.
  void add_wall(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double height, uint64_t texture_seed,
                double base_z = 0.0);
  /// A building: a box of footprint `length` x `depth` and `height`, centred at (x, y) with yaw [rad].
  void add_building(const Eigen::Vector2d& centre, double yaw, double length, double depth, double height,
                    uint64_t texture_seed, double base_z = 0.0);
  /// A moving textured box; returns its object id.
  int add_moving_box(const Eigen::Vector3d& size, PoseFunction pose, uint64_t texture_seed, BoxStyle style,
                     const std::string& name = "");
  /// A car, 4.5 x 1.8 x 1.5 m; returns its object id.
  int add_car(PoseFunction pose, uint64_t texture_seed);
  /// A box truck, 10 x 2.5 x 3.5 m; returns its object id.
  int add_truck(PoseFunction pose, uint64_t texture_seed);

  const std::vector<WorldObject>& objects() const { return objects_; }
  const WorldObject& object(int id) const { return objects_.at(static_cast<size_t>(id)); }
  const TextureDensity& density() const { return density_; }
  /// Total number of quads.
  size_t num_quads() const;
  /// Bytes held by the textures (each distinct texture counted once).
  size_t texture_bytes() const;

 private:
  TextureDensity density_;
  std::vector<WorldObject> objects_;
};

}  // namespace dynavins::sim
