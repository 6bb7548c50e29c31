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
  const Pose last = poses_.back();
  Pose next{t_ns, {}, {}};
  Eigen::Vector3d v_next;
  pre.predict(last.p, last.q, v_, ba_, bg_, gravity, next.p, next.q, v_next);
  poses_.push_back(next);
  v_ = v_next;
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
