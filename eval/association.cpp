#include "eval/association.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dynavins::eval {

namespace {

std::vector<double> stamps_of(const Trajectory& traj) {
  std::vector<double> t;
  t.reserve(traj.size());
  for (const StampedPose& p : traj.poses) t.push_back(p.t);
  if (!std::is_sorted(t.begin(), t.end())) {
    throw std::invalid_argument(traj.source + ": time stamps are not sorted, cannot associate");
  }
  return t;
}

// Index of the element of sorted `t` nearest to `s`; the first of equal candidates, as np.argmin.
std::size_t nearest(const std::vector<double>& t, double s) {
  const auto it = std::lower_bound(t.begin(), t.end(), s);
  std::size_t k = static_cast<std::size_t>(it - t.begin());
  if (k == t.size() || (k > 0 && std::fabs(t[k - 1] - s) <= std::fabs(t[k] - s))) {
    --k;
    while (k > 0 && t[k - 1] == t[k]) --k;
  }
  return k;
}

}  // namespace

Association associate(const Trajectory& gt, const Trajectory& est, double max_dt) {
  if (!(max_dt >= 0.0) || !std::isfinite(max_dt)) {
    throw std::invalid_argument("max time difference must be a finite number >= 0, got " + std::to_string(max_dt));
  }
  if (gt.empty() || est.empty()) {
    throw std::runtime_error((gt.empty() ? gt.source : est.source) + ": trajectory has no poses to associate");
  }
  const std::vector<double> t_gt = stamps_of(gt);
  const std::vector<double> t_est = stamps_of(est);

  // evo iterates over the trajectory with fewer poses (the ground truth on a tie).
  const bool est_longer = est.size() > gt.size();
  const std::vector<double>& t_short = est_longer ? t_gt : t_est;
  const std::vector<double>& t_long = est_longer ? t_est : t_gt;

  Association a;
  for (std::size_t i = 0; i < t_short.size(); ++i) {
    const std::size_t j = nearest(t_long, t_short[i]);
    if (std::fabs(t_long[j] - t_short[i]) <= max_dt) {
      a.gt_index.push_back(est_longer ? i : j);
      a.est_index.push_back(est_longer ? j : i);
    }
  }
  if (a.size() == 0) {
    throw std::runtime_error("no time stamps of " + est.source + " are within " + std::to_string(max_dt) +
                             " s of " + gt.source + " (do both use the same clock and unit?)");
  }
  spdlog::debug("associated {} of at most {} poses ({} vs {}, max dt {} s)", a.size(), t_short.size(), gt.source,
                est.source, max_dt);
  return a;
}

}  // namespace dynavins::eval
