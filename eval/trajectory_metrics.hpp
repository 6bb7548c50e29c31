#pragma once
// Error metrics on associated pose sequences: ATE (absolute translation) and RPE (relative).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

namespace dynavins::eval {

/// Summary statistics of a list of errors, defined as evo / numpy do (median of an even count
/// averages the two middle values; std is the population std, ddof = 0).
struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  ///< sum of squared errors
};

/// Statistics of `errors`; throws std::invalid_argument if it is empty.
ErrorStats error_stats(const std::vector<double>& errors);

/// |est_i - gt_i| for each associated pair (evo's APE, translation part); sizes must match.
std::vector<double> ate_translation_errors(const std::vector<Eigen::Vector3d>& gt,
                                           const std::vector<Eigen::Vector3d>& est);

/// Translation norm of E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j) over consecutive pairs
/// (i, j = i + delta) of indices 0, delta, 2 delta, ... (evo's RPE, frames, translation part).
/// Throws std::invalid_argument on size mismatch, delta == 0, or fewer than delta + 1 poses.
std::vector<double> rpe_translation_errors(const std::vector<Eigen::Isometry3d>& gt,
                                           const std::vector<Eigen::Isometry3d>& est, std::size_t delta);

}  // namespace dynavins::eval
