#include "stages/estimator/imu_path_from_rest.hpp"

#include <cmath>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

void ImuPathFromRest::anchor(int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q,
                             const Eigen::Vector3d& v, const Eigen::Vector3d& v_solved, const Eigen::Vector3d& ba,
                             const Eigen::Vector3d& bg) {
  poses_.assign(1, Pose{t_ns, p, q.normalized()});
  v_ = v;
  start_speed_gap_ = (v - v_solved).norm();
  ba_ = ba;
  bg_ = bg;
}

void ImuPathFromRest::extend(int64_t t_ns, const imu::ImuPreintegration& pre, double gravity) {
  if (poses_.empty()) return;
  Eigen::Vector3d alpha, beta;
  Eigen::Quaterniond gamma;
  pre.corrected_deltas(ba_, bg_, alpha, gamma, beta);
  const double T = pre.sum_dt();
  const Eigen::Vector3d g_w(0.0, 0.0, -gravity);
  const Pose last = poses_.back();
  // VINS-Mono §VI-B, as ImuPreintegration::evaluate_residual: Pj = Pi + Vi T + ½ g T² + Ri α, Vj = Vi + g T +
  // Ri β, Qj = Qi γ.
  poses_.push_back({t_ns, last.p + v_ * T + 0.5 * g_w * T * T + last.q * alpha, (last.q * gamma).normalized()});
  v_ += g_w * T + last.q * beta;
}

const ImuPathFromRest::Pose* ImuPathFromRest::after_anchor(int64_t t_ns) const {
  for (size_t i = 1; i < poses_.size(); ++i)
    if (poses_[i].t_ns == t_ns) return &poses_[i];
  return nullptr;
}

bool ImuPathFromRest::departed(int64_t t_ns, const Eigen::Vector3d& p, double acc_n) const {
  const Pose* on_path = after_anchor(t_ns);
  if (!on_path) return false;
  const double T = 1e-9 * static_cast<double>(t_ns - anchor_t_ns());
  const double sigma = acc_n * std::pow(T, 1.5) / std::sqrt(3.0);
  return (p - on_path->p).norm() > start_speed_gap_ * T + 3.0 * sigma;
}

}  // namespace dynavins::estimator
