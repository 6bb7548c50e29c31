#pragma once
// Real motion for the simulator: read a TUM trajectory (`t x y z qx qy qz qw`, plain text or gzip) and
// fit a SmoothTrajectory to a time window of it (see trajectory_fit.hpp for the fit itself).

#include <string>
#include <vector>

#include "sim/motion/smooth_trajectory.hpp"
#include "sim/motion/trajectory_fit.hpp"

namespace dynavins::sim {

/// Reads a TUM trajectory file; gzip-compressed files are detected and inflated transparently (zlib).
/// Blank lines and lines starting with '#' are skipped. Throws std::runtime_error naming the file and the
/// line for: unreadable file, a row without exactly 8 numbers, a non-finite value, a non-unit quaternion
/// (|q| off by > 1e-3), or a time not strictly after the previous one. Quaternions are returned normalised.
std::vector<TimedPose> read_tum_trajectory(const std::string& path);

/// Which part of a TUM file to use and how to fit it.
struct TumFitOptions {
  double window_start = 0.0;     ///< start of the window, seconds after the file's first pose
  double window_duration = 0.0;  ///< window length [s]; <= 0 means to the end of the file
  bool shift_to_zero = true;     ///< make time 0 the first pose of the window (else keep file time)
  /// Position steps whose excess over the local motion implies more than this acceleration [m/s^2] are
  /// ground-truth glitches (EuRoC MH_03/04/05 have steps of 0.4-13 cm when the laser tracker re-locks) and
  /// are removed by shifting the later samples; <= 0 disables. See remove_position_jumps.
  double glitch_acceleration = 50.0;
  TrajectoryFitOptions fit;      ///< spline fit settings
  /// Rigid placement applied to every sample before the fit: p' = world_from_file * p and
  /// R' = world_from_file.R * R * file_body_from_body, i.e. the file's world put into ours and the body
  /// axes renamed (the body origin stays where it was). Identity: the file as it is.
  Eigen::Isometry3d world_from_file = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d file_body_from_body = Eigen::Matrix3d::Identity();
};

/// What fit_tum_trajectory did.
struct TumFitReport {
  TrajectoryFitReport fit;   ///< residuals are against the (de-glitched) samples of the window
  double time_offset = 0.0;  ///< file time of trajectory time 0 [s] (0 if shift_to_zero is false)
  int removed_jumps = 0;     ///< number of position glitches removed
};

/// Selects the samples of a window of a pose list (times as in the list). Throws std::invalid_argument if
/// the window holds fewer than 2 poses.
std::vector<TimedPose> select_window(const std::vector<TimedPose>& poses, double window_start, double window_duration);

/// Removes isolated position steps: a step p_m - p_{m-1} is compared with the per-axis median velocity of
/// the three steps before and after it times the step's duration dt. Smooth motion leaves an excess of
/// about |a| dt^2, so an excess larger than max(min_jump, 3 glitch_acceleration dt^2) [m] is a glitch and
/// is subtracted from p_m and all later samples. A single outlier sample is thus removed too (its return
/// step cancels the shift). Steps longer than 1.5 times the median interval (dropouts) are left alone.
/// Returns how many steps were corrected; glitch_acceleration <= 0 disables.
int remove_position_jumps(std::vector<TimedPose>& poses, double glitch_acceleration, double min_jump = 1e-3);

/// Reads `path`, takes the window, removes glitches, optionally shifts time, and fits the spline.
SmoothTrajectory fit_tum_trajectory(const std::string& path, const TumFitOptions& options = {},
                                  TumFitReport* report = nullptr);

}  // namespace dynavins::sim
