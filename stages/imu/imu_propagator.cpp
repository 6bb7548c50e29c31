#include "stages/imu/imu_propagator.hpp"

#include <cmath>

#include "stages/imu/imu_sample_interpolation.hpp"

namespace dynavins::imu {

ImuPropagator::ImuPropagator(ImuPropagatorOptions options) : opt_(options) {}

void ImuPropagator::reset(const NavState& state) {
  initialized_ = true;
  state_ = state;
  have_last_ = false;
  // Measurement at the state time: interpolated between the bracketing samples of the history.
  for (size_t k = 0; k + 1 < history_.size(); ++k) {
    const ImuSample &a = history_[k], &b = history_[k + 1];
    if (a.t_ns <= state.t_ns && state.t_ns <= b.t_ns) {
      last_ = interpolate(a, b, state.t_ns);
      have_last_ = true;
      break;
    }
  }
  if (!have_last_ && !history_.empty() && history_.back().t_ns == state.t_ns) {
    last_ = history_.back();
    have_last_ = true;
  }
  for (const ImuSample& s : history_)
    if (s.t_ns > state.t_ns) step(s);
}

std::optional<NavState> ImuPropagator::add_imu(const ImuSample& s) {
  if (!history_.empty() && s.t_ns <= history_.back().t_ns) {
    ++rejected_;
    return std::nullopt;
  }
  history_.push_back(s);
  while (history_.size() > 2 && history_.back().t_ns - history_[1].t_ns > opt_.history_ns) history_.pop_front();
  if (!initialized_ || s.t_ns <= state_.t_ns) return std::nullopt;
  step(s);
  return state_;
}

std::optional<NavState> ImuPropagator::latest() const {
  if (!initialized_) return std::nullopt;
  return state_;
}

void ImuPropagator::step(const ImuSample& s) {
  // Without a measurement at the state time (history too short), hold the first later one constant.
  const ImuSample& s0 = have_last_ ? last_ : s;
  const double dt = static_cast<double>(s.t_ns - state_.t_ns) * 1e-9;
  const Eigen::Vector3d g_w(0.0, 0.0, -opt_.gravity);
  // Midpoint rule in the world frame (VINS-Mono §IV-B kinematics, discretised as Estimator::fastPredict does).
  const Eigen::Vector3d a0 = state_.q_wb * (s0.acc - state_.bias_acc) + g_w;
  const Eigen::Vector3d w = 0.5 * (s0.gyr + s.gyr) - state_.bias_gyr;
  const double angle = w.norm() * dt;
  Eigen::Quaterniond dq = Eigen::Quaterniond::Identity();
  if (angle > 1e-15) dq = Eigen::Quaterniond(Eigen::AngleAxisd(angle, w.normalized()));
  const Eigen::Quaterniond q1 = (state_.q_wb * dq).normalized();
  const Eigen::Vector3d a1 = q1 * (s.acc - state_.bias_acc) + g_w;
  const Eigen::Vector3d a = 0.5 * (a0 + a1);
  state_.p_wb += state_.v_wb * dt + 0.5 * a * dt * dt;
  state_.v_wb += a * dt;
  state_.q_wb = q1;
  state_.t_ns = s.t_ns;
  last_ = s;
  have_last_ = true;
}

}  // namespace dynavins::imu
