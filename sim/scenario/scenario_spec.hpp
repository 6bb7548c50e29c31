#pragma once
// A scenario file (bench/scenarios/*.yaml, OpenCV FileStorage YAML): the world, the rig's path,
// the moving objects and the lighting of one synthetic sequence. Deterministic for a seed.
// Unknown or missing keys are errors naming the key and the file.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynavins::sim {

/// How a moving object moves (see scenario_builder.cpp for the exact poses).
enum class ObjectMotion {
  Lane,        ///< straight along world x: x = x0 + speed (t - t0) at lateral y
  CrossAhead,  ///< crosses the rig's path `distance` ahead of it at time t, at lateral `speed`
  Follow,      ///< stays `distance` ahead of the rig (and `offset` to its left), facing its heading
  Relocate,    ///< parked, moved while unseen: piecewise-constant poses (t_from, x, y, yaw_deg)
};

enum class ObjectKind { Car, Truck, Board };

struct MovingObjectSpec {
  ObjectKind kind = ObjectKind::Car;
  ObjectMotion motion = ObjectMotion::Lane;
  double x0 = 0, y = 0, speed = 0, t0 = 0;      ///< Lane
  double t = 0, distance = 5, offset = 0;       ///< CrossAhead (t, distance, speed), Follow (distance, offset)
  std::vector<Eigen::Vector4d> poses;           ///< Relocate: (t_from, x, y, yaw_deg)
};

struct ScenarioSpec {
  std::string name;
  std::string file;  ///< where it was loaded from
  uint64_t seed = 1;
  double duration = 0;  ///< [s]; 0 = the whole path
  // World: the street preset (avenues along x crossed by streets along y, buildings, parked cars).
  double world_x_min = -40, world_x_max = 160;
  uint64_t world_seed = 7;
  std::vector<double> avenue_y{0.0};         ///< world.avenues: y of each avenue [m]
  std::vector<double> cross_street_x{60.0};  ///< world.cross_streets: x of each cross street [m]
  // Motion of the body (IMU) frame: a geometric path (x, y, z corners) with a motion profile.
  std::string profile = "drone";  ///< car | drone | handheld
  double cruise_speed = 0;        ///< [m/s]; 0 = the profile's
  std::vector<Eigen::Vector3d> waypoints;
  std::vector<double> dwell;  ///< per waypoint: stand still there this long [s] (0: drive through)
  // ... or recorded motion: a TUM trajectory (e.g. EuRoC ground truth) fitted and placed in the street,
  // so the sim also runs the roll, pitch and shake of a real platform (motion.tum instead of waypoints).
  std::string tum_file;     ///< resolved path of motion.tum; empty = waypoints
  double tum_start = 0;     ///< [s] after the file's first pose
  Eigen::Vector4d tum_placement = Eigen::Vector4d::Zero();  ///< x, y, z [m], yaw [deg] of the file's world in ours
  std::string tum_body_axes = "sim";  ///< sim: camera along body x; euroc: along the IMU's z, as on the EuRoC MAV
  std::string photometric = "day";  ///< day | night
  std::string rig = "euroc";        ///< euroc | viode (StereoRig::preset)
  std::vector<MovingObjectSpec> objects;
};

/// Reads a scenario file. Throws std::runtime_error naming the file and the key at fault.
ScenarioSpec load_scenario(const std::string& path);

}  // namespace dynavins::sim
