#pragma once
// Time association of an estimate with its ground truth, matching evo's associate_trajectories.

#include "eval/trajectory.hpp"

#include <cstddef>
#include <vector>

namespace dynavins::eval {

/// Matched pose pairs: gt.poses[gt_index[k]] goes with est.poses[est_index[k]], in time order.
struct Association {
  std::vector<std::size_t> gt_index;
  std::vector<std::size_t> est_index;

  std::size_t size() const { return gt_index.size(); }
};

/// evo's rule: each pose of the trajectory with fewer poses takes the nearest-in-time pose of the
/// other (the earliest one on a tie) when |dt| <= max_dt seconds. Throws std::runtime_error
/// naming both sources when nothing matches, std::invalid_argument on unsorted input or bad max_dt.
Association associate(const Trajectory& gt, const Trajectory& est, double max_dt = 0.01);

}  // namespace dynavins::eval
