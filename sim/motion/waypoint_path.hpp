#pragma once
// Scripted motion for scenario files.
//
// 1. Timed waypoints (t, position, yaw, pitch, roll): fitted by the smoothing spline of trajectory_fit.hpp,
//    i.e. the minimum-jerk curve through them. Good for dense or gently varying scripts; with sparse sharp
//    corners it swings wide like any interpolating spline, so use 2. for those.
// 2. A geometric path (sparse corners, no times) plus a motion profile: the polyline's corners are rounded
//    with circular arcs, a speed profile obeys cruise speed, lateral / longitudinal acceleration and yaw-rate
//    limits (forward-backward pass, as in time-optimal path following), sharp corners and dwell points become
//    stops (turning in place with a quintic smoothstep). The result is sampled densely, filtered with a
//    triangle kernel in time (acceleration steps become ramps: bounded jerk) and fitted by the spline. No
//    overshoot: a positive kernel averages accelerations, so the limits still hold after filtering, and the
//    spline follows a curve that is already smooth (the tests check the limits on the final spline).
// Body frame convention of these paths: x forward, y left, z up; R_wb = Rz(yaw) Ry(pitch) Rx(roll).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "sim/motion/smooth_trajectory.hpp"
#include "sim/motion/trajectory_fit.hpp"

namespace dynavins::sim {

/// Fit settings for scripted (noise-free) samples: knot spacing 0.1 s.
TrajectoryFitOptions default_script_fit_options();

/// One scripted pose at a given time.
struct Waypoint {
  double t = 0.0;                               ///< [s]
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position [m]
  double yaw = 0.0, pitch = 0.0, roll = 0.0;    ///< [rad], R = Rz(yaw) Ry(pitch) Rx(roll)
};

/// Fits the minimum-jerk spline through timed waypoints (times strictly increasing; consecutive
/// orientations < 0.9 pi apart). Default fit: knot spacing 0.1 s, waypoints matched to about 1 mm.
SmoothTrajectory trajectory_from_timed_waypoints(const std::vector<Waypoint>& waypoints,
                                              const TrajectoryFitOptions& fit = default_script_fit_options(),
                                              TrajectoryFitReport* report = nullptr);

/// A corner of a geometric path.
struct PathWaypoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  ///< position [m]
  std::optional<double> yaw;                    ///< [rad]; required by HeadingMode::kWaypoints, else unused
  double pitch = 0.0, roll = 0.0;               ///< [rad], interpolated along the path
  double dwell = 0.0;                           ///< stop here and stay this long [s] (> 0 forces a stop)
  bool stop = false;                            ///< come to rest here even without a dwell
};

/// How the body yaw is chosen along a path.
enum class HeadingMode {
  kAlongPath,  ///< yaw = direction of travel (+ yaw_offset); turns in place at stops (car, walker, drone)
  kWaypoints,  ///< yaw interpolated along the path between the waypoints' yaws (shortest way)
};

/// Speed and comfort limits of a path. Presets: car(), drone(), handheld().
struct PathProfile {
  double cruise_speed = 1.0;          ///< [m/s]
  double max_lateral_acc = 1.0;       ///< on rounded corners [m/s^2]
  double max_longitudinal_acc = 0.5;  ///< speeding up and braking [m/s^2]
  double corner_radius = 1.0;         ///< rounding radius [m]; shrunk to fit half of the shorter adjacent leg
  double max_yaw_rate = 0.8;          ///< [rad/s], also the peak rate of turns in place
  double max_corner_angle = 2.6;      ///< corners turning more than this [rad] are not rounded but stops
  double start_dwell = 1.0;           ///< standing still before moving [s]
  double end_dwell = 1.0;             ///< standing still at the end [s]
  HeadingMode heading = HeadingMode::kAlongPath;
  double yaw_offset = 0.0;            ///< added to the travel direction in kAlongPath [rad]
  /// The dense path is filtered in time with a triangle kernel of this width [s] (two box passes). A
  /// positive kernel averages velocities, accelerations and rates, so it never exceeds the limits above,
  /// while it turns their steps into ramps: jerk <= 2 * (acceleration step) / smoothing_time.
  double smoothing_time = 0.6;
  double sample_dt = 0.01;            ///< spacing of the dense samples handed to the fit [s]
  TrajectoryFitOptions fit = default_script_fit_options();

  static PathProfile car();       ///< 8 m/s, 2.5 m/s^2 lateral, 1.5 m/s^2 longitudinal, 8 m corners, 1.2 s smoothing
  static PathProfile drone();     ///< 1.5 m/s, 1.5 / 1.0 m/s^2, 1 m corners, 0.6 s smoothing
  static PathProfile handheld();  ///< 1.2 m/s walking, 1.0 / 0.8 m/s^2, 0.6 m corners, 0.5 s smoothing
};

/// Dense, time-stamped poses (every sample_dt, from t = 0) of the rounded, speed-profiled, smoothed path.
/// The end dwell is lengthened by less than sample_dt so that the last sample falls on the grid.
/// Throws std::invalid_argument for fewer than 2 waypoints, coincident consecutive waypoints, non-finite
/// values, a missing yaw in kWaypoints mode, or non-positive limits.
std::vector<TimedPose> densify_path(const std::vector<PathWaypoint>& waypoints, const PathProfile& profile);

/// densify_path followed by fit_trajectory with profile.fit.
SmoothTrajectory trajectory_from_path(const std::vector<PathWaypoint>& waypoints, const PathProfile& profile,
                                    TrajectoryFitReport* report = nullptr);

}  // namespace dynavins::sim
