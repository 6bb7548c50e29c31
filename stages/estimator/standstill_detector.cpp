#include "stages/estimator/standstill_detector.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

void ImuStillVelocity::add(const imu::ImuPreintegration& pre, const Eigen::Quaterniond& q, const Eigen::Vector3d& ba,
                           const Eigen::Vector3d& bg, double gravity) {
  if (!has_biases_) {
    ba_ = ba;
    bg_ = bg;
    has_biases_ = true;
  }
  // Only the velocity is wanted; the position is the origin's (unused).
  Eigen::Vector3d p_unused;
  Eigen::Quaterniond q_unused;
  const Eigen::Vector3d v_kept = std::exp(-pre.sum_dt() / kForgetS) * v_;
  pre.predict(Eigen::Vector3d::Zero(), q, v_kept, ba_, bg_, gravity, p_unused, q_unused, v_);
}

StandstillCheck check_standstill(const WindowFeatures& features, int newest, const Eigen::Matrix3d& R_prev_new,
                                double speed, const StandstillOptions& options) {
  StandstillCheck c;
  if (newest < 1) return c;
  std::vector<double> disparity;
  for (const auto& [id, f] : features.all()) {
    if (f.end_slot() != newest || f.start_slot > newest - 1 || f.weight < options.min_weight) continue;
    const Eigen::Vector2d& xy_prev = f.obs[newest - 1 - f.start_slot].xy;
    const Eigen::Vector2d& xy_new = f.obs.back().xy;
    // The newest bearing seen from the previous camera's orientation: what is left is translation (or
    // the point's own motion).
    const Eigen::Vector3d b = R_prev_new * Eigen::Vector3d(xy_new.x(), xy_new.y(), 1.0);
    if (b.z() <= 1e-6) continue;
    disparity.push_back(kNominalFocalPx * (b.head<2>() / b.z() - xy_prev).norm());
  }
  c.features = static_cast<int>(disparity.size());
  if (disparity.empty()) return c;
  auto mid = disparity.begin() + disparity.size() / 2;
  std::nth_element(disparity.begin(), mid, disparity.end());
  c.median_disparity_px = *mid;
  c.still = options.enabled && c.features >= options.min_features &&
            c.median_disparity_px < options.max_disparity_px && speed < options.max_speed;
  return c;
}

}  // namespace dynavins::estimator
