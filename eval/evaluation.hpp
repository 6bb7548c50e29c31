#pragma once
// The whole evaluation of an estimate against ground truth: associate, align, ATE and RPE.

#include "eval/association.hpp"
#include "eval/trajectory.hpp"
#include "eval/trajectory_metrics.hpp"
#include "eval/umeyama.hpp"

#include <string>
#include <vector>

namespace dynavins::eval {

/// How the estimate is aligned to the ground truth before computing errors.
enum class Alignment { None, SE3, Sim3 };

/// Parses "none", "se3" or "sim3" (case-insensitive); throws std::invalid_argument otherwise.
Alignment parse_alignment(const std::string& name);

/// Lower-case name of an alignment, as accepted by parse_alignment().
const char* alignment_name(Alignment a);

/// Settings of evaluate(); the defaults are evo's.
struct EvalOptions {
  Alignment align = Alignment::SE3;
  double max_dt = 0.01;       ///< association tolerance [s]
  std::size_t rpe_delta = 1;  ///< RPE step [frames of the associated sequence]
};

/// Everything evaluate() measured.
struct EvalResult {
  std::size_t gt_poses = 0;
  std::size_t est_poses = 0;
  Association association;
  Similarity3 alignment;  ///< maps estimate coordinates into the ground-truth frame
  std::vector<double> ate_errors;
  std::vector<double> rpe_errors;
  ErrorStats ate;
  ErrorStats rpe;
};

/// Applies `T` to every pose of `traj`: p -> s R p + t, q -> R q (evo's trajectory align).
Trajectory transformed(const Trajectory& traj, const Similarity3& T);

/// Associates, aligns the matched estimate with Umeyama (or not) and computes ATE and RPE
/// translation errors like evo_ape / evo_rpe. Throws std::runtime_error / invalid_argument
/// when there are no matches or too few to align or to form one RPE pair.
EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options = {});

}  // namespace dynavins::eval
