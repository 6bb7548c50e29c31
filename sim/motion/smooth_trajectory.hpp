#pragma once
// SmoothTrajectory: the true body motion T_world_body(t) of a simulated run.
// Position: uniform cubic B-spline in R^3; orientation: cumulative cubic B-spline on SO(3), sharing the
// knot grid. Both are C2, so velocity, acceleration, angular velocity and angular acceleration are exact
// analytic functions and the IMU derived from them is consistent with the pose to machine precision.
//
// Frames and units: world is z-up (gravity along -z), body = IMU frame; the simulator's scripted paths
// use body x forward, y left, z up. Time is in seconds (double) relative to the trajectory's own origin;
// the IMU simulator maps it to int64 nanoseconds as t_ns = round(t * 1e9).

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/motion/bspline_r3.hpp"
#include "sim/motion/bspline_so3.hpp"

namespace dynavins::sim {

/// Full kinematic state of the body at one time, world frame unless named _b (body frame).
struct KinematicState {
  double t = 0.0;
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();    ///< position [m]
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();    ///< velocity [m/s]
  Eigen::Vector3d a_w = Eigen::Vector3d::Zero();    ///< acceleration [m/s^2] (no gravity)
  Eigen::Vector3d j_w = Eigen::Vector3d::Zero();    ///< jerk [m/s^3]
  Eigen::Matrix3d R_wb = Eigen::Matrix3d::Identity();  ///< orientation
  Eigen::Vector3d omega_b = Eigen::Vector3d::Zero();   ///< angular velocity [rad/s]
  Eigen::Vector3d alpha_b = Eigen::Vector3d::Zero();   ///< angular acceleration [rad/s^2]
};

/// A C2 pose trajectory with exact derivatives.
class SmoothTrajectory {
 public:
  SmoothTrajectory() = default;
  /// Builds from splines that must share one knot grid (same t0, dt and number of control points).
  SmoothTrajectory(BSplineR3 position, BSplineSO3 orientation);

  /// Start / end of the valid time range [s].
  double t_min() const { return pos_.knots().t_min(); }
  double t_max() const { return pos_.knots().t_max(); }
  /// Duration t_max - t_min [s].
  double duration() const { return t_max() - t_min(); }
  /// Knot spacing [s].
  double knot_spacing() const { return pos_.knots().dt(); }

  /// Everything at time t (throws std::out_of_range outside [t_min, t_max]).
  KinematicState evaluate(double t) const;
  /// Position p_wb(t) [m].
  Eigen::Vector3d position(double t) const { return pos_.evaluate(t).p; }
  /// Velocity in the world [m/s].
  Eigen::Vector3d velocity(double t) const { return pos_.evaluate(t).v; }
  /// Acceleration in the world, without gravity [m/s^2].
  Eigen::Vector3d acceleration(double t) const { return pos_.evaluate(t).a; }
  /// Orientation R_wb(t).
  Eigen::Matrix3d rotation(double t) const { return rot_.evaluate(t).R; }
  /// Orientation q_wb(t).
  Eigen::Quaterniond orientation(double t) const { return Eigen::Quaterniond(rotation(t)); }
  /// Body angular velocity ω_b(t) [rad/s].
  Eigen::Vector3d angular_velocity(double t) const { return rot_.evaluate(t).omega; }
  /// Pose T_world_body(t).
  Eigen::Isometry3d pose(double t) const;
  /// The same motion with time shifted: the new trajectory at t + offset equals this one at t.
  SmoothTrajectory shifted_in_time(double offset) const;

  const BSplineR3& position_spline() const { return pos_; }        ///< the position spline
  const BSplineSO3& orientation_spline() const { return rot_; }  ///< the orientation spline

 private:
  BSplineR3 pos_;
  BSplineSO3 rot_;
};

}  // namespace dynavins::sim
