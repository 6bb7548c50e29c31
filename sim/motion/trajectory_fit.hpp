#pragma once
// Least-squares fit of a SmoothTrajectory to timed poses (mocap ground truth, or dense scripted samples).
//
// Cost (a MAP estimate under white-jerk priors, i.e. a quintic-type smoothing spline on the cubic basis):
//   Σ_m |p(t_m) - p_m|^2 / σ_p^2 + Σ_m |Log(R_m^T R(t_m))|^2 / σ_r^2
//   + Σ_i |-c_i + 3c_{i+1} - 3c_{i+2} + c_{i+3}|^2 / (q_j dt^5) + Σ_i |d_i - 2d_{i+1} + d_{i+2}|^2 / (q_ω dt^5)
// where c_k are the position control points and d_k = Log(R_k^T R_{k+1}) the rotation increments.
// (-c_i + 3c_{i+1} - 3c_{i+2} + c_{i+3}) / dt^3 is the exact (constant) jerk of segment i, so the third term
// is ∫|jerk|^2 dt / q_j; the fourth is its SO(3) analogue. Penalising jerk rather than acceleration leaves
// the acceleration free at the ends of the data (no pull towards rest) and fills gaps with minimum-jerk
// motion. Position is linear least squares; orientation is Gauss-Newton on right perturbations
// R_k Exp(δ_k), starting from slerp of the data.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/motion/smooth_trajectory.hpp"

namespace dynavins::sim {

/// One pose sample T_world_body at time t [s].
struct TimedPose {
  double t = 0.0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

/// Settings of the spline fit. Defaults suit 100-200 Hz motion capture of a MAV or a hand-held rig.
/// The knot spacing is the main smoother: it sets the bandwidth (about 1/(3 dt), ~7 Hz at 0.05 s). White
/// position noise σ at sample rate f becomes acceleration noise of roughly
/// 1.1 m/s^2 * (σ / 1 mm) * sqrt(f / 200 Hz) * (dt / 0.05 s)^-2.5 (measured, see test_trajectory_fit.cpp);
/// use a larger spacing for noisy data. The prior is light: it only regularises gaps and the ends.
/// On EuRoC V1_01 the defaults give an IMU matching the real ADIS16448 to 0.01 rad/s and 0.1 m/s^2 RMS
/// (low-passed at ~10 Hz), see test_tum_trajectory.cpp.
struct TrajectoryFitOptions {
  double knot_spacing = 0.05;       ///< nominal knot spacing [s]; the exact one divides the data span evenly
  double position_sigma = 1e-3;     ///< position noise of the samples [m] (nominal mocap accuracy)
  double rotation_sigma = 2e-3;     ///< orientation noise of the samples [rad]
  double jerk_psd = 1e4;             ///< prior PSD q_j of the jerk [m^2/s^5]
  double angular_jerk_psd = 1e4;     ///< prior PSD q_ω of the angular jerk [rad^2/s^5]
  int max_iterations = 30;           ///< Gauss-Newton iterations for the orientation
};

/// How well the fit matches its data (evaluated at the sample times).
struct TrajectoryFitReport {
  int num_samples = 0;
  int num_control_points = 0;
  double knot_spacing = 0.0;       ///< the knot spacing actually used [s]
  double position_rms = 0.0;       ///< RMS of |p(t_m) - p_m| [m]
  double position_max = 0.0;       ///< max of |p(t_m) - p_m| [m]
  double rotation_rms = 0.0;       ///< RMS of |Log(R_m^T R(t_m))| [rad]
  double rotation_max = 0.0;       ///< max of the same [rad]
  double max_acceleration = 0.0;   ///< max |a_w| at the sample times [m/s^2]
  double max_angular_velocity = 0.0;  ///< max |ω_b| at the sample times [rad/s]
  int gauss_newton_iterations = 0;
  bool converged = false;
};

/// Fits a SmoothTrajectory spanning exactly [poses.front().t, poses.back().t].
/// Needs >= 2 poses with strictly increasing, finite times and unit quaternions, and consecutive
/// orientations less than pi apart (throws std::invalid_argument naming the offending index otherwise).
SmoothTrajectory fit_trajectory(const std::vector<TimedPose>& poses, const TrajectoryFitOptions& options = {},
                               TrajectoryFitReport* report = nullptr);

}  // namespace dynavins::sim
