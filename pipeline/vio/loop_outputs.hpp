#pragma once
// The loop closer's part of a run's outputs (issue: loop closure): trajectory.tum, the estimate of every
// frame after the final pose-graph optimisation (the odometry itself when loop closure is off), and
// loops.csv, every verified loop with its group, hypothesis and final weight, and on input with ground
// truth whether it is true.

#include <string>

#include "eval/trajectory.hpp"
#include "pipeline/vio/loop_stage.hpp"

namespace dynavins::pipeline {

/// The odometry corrected with the keyframe corrections (T_corr of the latest keyframe at or before each
/// frame); the odometry itself without a loop summary.
eval::Trajectory corrected_trajectory(const eval::Trajectory& odometry, const LoopRunSummary* loop);

/// A loop is counted true when its relative pose T_m^k is within these of the ground truth's.
inline constexpr double kTrueLoopMaxErrorM = 0.3, kTrueLoopMaxErrorDeg = 5.0;

/// What loops.csv found against ground truth (all zero without ground truth).
struct LoopTruthCounts {
  int true_loops = 0, false_loops = 0;
  int false_used = 0;  ///< false loops the final optimisation used with weight >= 0.5
  int true_used = 0;   ///< true loops the final optimisation used with weight >= 0.5
  /// Loops at weight >= 0.5, used or not (with the correction skipped as insignificant none is used).
  int false_adopted = 0, true_adopted = 0;
};

/// Writes loops.csv to `path`; `truth` may be empty (no ground truth: the truth columns stay empty).
/// Throws std::runtime_error naming the file on a write error.
LoopTruthCounts write_loops_csv(const std::string& path, const LoopRunSummary& loop, const eval::Trajectory& truth);

/// summary.json's "loop" object.
std::string loop_json(const LoopRunSummary& loop, const LoopTruthCounts& truth, bool has_truth);

}  // namespace dynavins::pipeline
