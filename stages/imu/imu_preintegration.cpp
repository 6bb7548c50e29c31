#include "stages/imu/imu_preintegration.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "stages/common/so3.hpp"

namespace dynavins::imu {
namespace {

using so3::right_jacobian;  // Exp(φ + δ) ≈ Exp(φ) Exp(Jr(φ) δ) (Forster et al. 2017, §II-A)

// Exact quaternion exponential; VINS uses the first-order (1, θ/2) form, equal to first order, so the
// Jacobians below are unchanged while large rates lose no accuracy.
Eigen::Quaterniond exp_q(const Eigen::Vector3d& theta) {
  const double a = theta.norm();
  if (a < 1e-12) return Eigen::Quaterniond(1.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(a, theta / a));
}

}  // namespace

ImuPreintegration::ImuPreintegration(const ImuSample& first, const Eigen::Vector3d& ba, const Eigen::Vector3d& bg,
                                     const ImuNoiseParams& noise)
    : noise_(noise), ba_(ba), bg_(bg), t_begin_ns_(first.t_ns) {
  samples_.push_back(first);
  // Noise vector [n_a0, n_g0, n_a1, n_g1, n_ba, n_bg] (VINS-Mono §IV-B, extended to the midpoint's two ends).
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  noise_cov_.block<3, 3>(0, 0) = noise.acc_n * noise.acc_n * I;
  noise_cov_.block<3, 3>(3, 3) = noise.gyr_n * noise.gyr_n * I;
  noise_cov_.block<3, 3>(6, 6) = noise.acc_n * noise.acc_n * I;
  noise_cov_.block<3, 3>(9, 9) = noise.gyr_n * noise.gyr_n * I;
  noise_cov_.block<3, 3>(12, 12) = noise.acc_w * noise.acc_w * I;
  noise_cov_.block<3, 3>(15, 15) = noise.gyr_w * noise.gyr_w * I;
}

ImuPreintegration::ImuPreintegration(const PreintegratedDeltas& d)
    : ImuPreintegration(d.samples.empty() ? ImuSample{} : d.samples.front(), d.ba, d.bg,
                        ImuNoiseParams{d.acc_n, d.gyr_n, d.acc_w, d.gyr_w}) {
  if (d.samples.empty()) samples_.clear();
  else samples_ = d.samples;
  alpha_ = d.alpha;
  gamma_ = d.gamma;
  beta_ = d.beta;
  covariance_ = d.covariance;
  jacobian_ = d.jacobian;
  sum_dt_ = d.sum_dt;
}

PreintegratedDeltas ImuPreintegration::deltas() const {
  PreintegratedDeltas d;
  d.samples = samples_;
  d.ba = ba_;
  d.bg = bg_;
  d.acc_n = noise_.acc_n;
  d.gyr_n = noise_.gyr_n;
  d.acc_w = noise_.acc_w;
  d.gyr_w = noise_.gyr_w;
  d.alpha = alpha_;
  d.gamma = gamma_;
  d.beta = beta_;
  d.covariance = covariance_;
  d.jacobian = jacobian_;
  d.sum_dt = sum_dt_;
  return d;
}

void ImuPreintegration::reset() {
  alpha_.setZero();
  beta_.setZero();
  gamma_.setIdentity();
  covariance_.setZero();
  jacobian_.setIdentity();
  sum_dt_ = 0.0;
}

void ImuPreintegration::integrate(const ImuSample& s) {
  if (samples_.empty()) throw std::logic_error("ImuPreintegration::integrate: not started with a first sample");
  if (s.t_ns <= samples_.back().t_ns)
    throw std::invalid_argument("ImuPreintegration::integrate: sample at " + std::to_string(s.t_ns) +
                                " ns not after " + std::to_string(samples_.back().t_ns) + " ns");
  const ImuSample prev = samples_.back();
  samples_.push_back(s);
  midpoint_step(prev, s);
}

void ImuPreintegration::repropagate(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) {
  ba_ = ba;
  bg_ = bg;
  reset();
  for (size_t k = 1; k < samples_.size(); ++k) midpoint_step(samples_[k - 1], samples_[k]);
}

void ImuPreintegration::midpoint_step(const ImuSample& s0, const ImuSample& s1) {
  const double dt = static_cast<double>(s1.t_ns - s0.t_ns) * 1e-9;
  // Midpoint mean propagation (VINS-Mono §IV-B discretised with the midpoint rule, as IntegrationBase does).
  const Eigen::Vector3d a0 = s0.acc - ba_, a1 = s1.acc - ba_;
  const Eigen::Vector3d w = 0.5 * (s0.gyr + s1.gyr) - bg_;
  const Eigen::Quaterniond dq = exp_q(w * dt);
  const Eigen::Quaterniond g1 = (gamma_ * dq).normalized();
  const Eigen::Matrix3d R0 = gamma_.toRotationMatrix(), R1 = g1.toRotationMatrix();
  const Eigen::Vector3d acc = 0.5 * (R0 * a0 + R1 * a1);
  const Eigen::Vector3d alpha1 = alpha_ + beta_ * dt + 0.5 * acc * dt * dt;
  const Eigen::Vector3d beta1 = beta_ + acc * dt;

  // Linearised error dynamics x_{k+1} = F x_k + V n_k (VINS-Mono §IV-B covariance/Jacobian recursion with the midpoint terms of
  // IntegrationBase::midPointIntegration). With right perturbations R1_true = R1 Exp(ΔR^T δθ - Jr(w dt) dt δbg)
  // (Forster §II-A, right Jacobian), so R1 a1 moves by -R1 [a1]x (ΔR^T δθ - Jr dt δbg). VINS takes ΔR^T ≈ I - [w]x dt and
  // Jr ≈ I; the exact factors cost nothing and make F the exact derivative of the discrete step, so the bias
  // correction is second-order accurate (checked in tests/imu).
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Ra0 = R0 * so3::hat(a0), Ra1 = R1 * so3::hat(a1);
  const Eigen::Matrix3d dRt = dq.toRotationMatrix().transpose();
  const Eigen::Matrix3d Jr = right_jacobian(w * dt);
  const double dt2 = dt * dt;
  Matrix15 F = Matrix15::Identity();
  F.block<3, 3>(kP, kR) = -0.25 * (Ra0 + Ra1 * dRt) * dt2;
  F.block<3, 3>(kP, kV) = I * dt;
  F.block<3, 3>(kP, kBa) = -0.25 * (R0 + R1) * dt2;
  F.block<3, 3>(kP, kBg) = 0.25 * Ra1 * Jr * dt2 * dt;
  F.block<3, 3>(kR, kR) = dRt;
  F.block<3, 3>(kR, kBg) = -Jr * dt;
  F.block<3, 3>(kV, kR) = -0.5 * (Ra0 + Ra1 * dRt) * dt;
  F.block<3, 3>(kV, kBa) = -0.5 * (R0 + R1) * dt;
  F.block<3, 3>(kV, kBg) = 0.5 * Ra1 * Jr * dt2;

  // Noise columns [n_a0, n_g0, n_a1, n_g1, n_ba, n_bg]; each gyro sample enters w with weight 1/2.
  Eigen::Matrix<double, 15, 18> V = Eigen::Matrix<double, 15, 18>::Zero();
  V.block<3, 3>(kP, 0) = 0.25 * R0 * dt2;
  V.block<3, 3>(kP, 3) = -0.125 * Ra1 * Jr * dt2 * dt;
  V.block<3, 3>(kP, 6) = 0.25 * R1 * dt2;
  V.block<3, 3>(kP, 9) = V.block<3, 3>(kP, 3);
  V.block<3, 3>(kR, 3) = 0.5 * Jr * dt;
  V.block<3, 3>(kR, 9) = 0.5 * Jr * dt;
  V.block<3, 3>(kV, 0) = 0.5 * R0 * dt;
  V.block<3, 3>(kV, 3) = -0.25 * Ra1 * Jr * dt2;
  V.block<3, 3>(kV, 6) = 0.5 * R1 * dt;
  V.block<3, 3>(kV, 9) = V.block<3, 3>(kV, 3);
  V.block<3, 3>(kBa, 12) = I * dt;
  V.block<3, 3>(kBg, 15) = I * dt;

  jacobian_ = F * jacobian_;
  covariance_ = F * covariance_ * F.transpose() + V * noise_cov_ * V.transpose();
  alpha_ = alpha1;
  beta_ = beta1;
  gamma_ = g1;
  sum_dt_ += dt;
}

bool ImuPreintegration::bias_moved_far(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, double ba_threshold,
                                     double bg_threshold) const {
  return (ba - ba_).norm() > ba_threshold || (bg - bg_).norm() > bg_threshold;
}

void ImuPreintegration::corrected_deltas(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg,
                                        Eigen::Vector3d& alpha, Eigen::Quaterniond& gamma,
                                        Eigen::Vector3d& beta) const {
  const Eigen::Vector3d dba = ba - ba_, dbg = bg - bg_;
  // Δ(b) ≈ Δ(b̄) + J δb, rotation through Exp (Forster §VI-C; VINS-Mono §IV-B).
  alpha = alpha_ + jacobian_.block<3, 3>(kP, kBa) * dba + jacobian_.block<3, 3>(kP, kBg) * dbg;
  beta = beta_ + jacobian_.block<3, 3>(kV, kBa) * dba + jacobian_.block<3, 3>(kV, kBg) * dbg;
  gamma = (gamma_ * exp_q(jacobian_.block<3, 3>(kR, kBg) * dbg)).normalized();
}

void ImuPreintegration::predict(const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi, const Eigen::Vector3d& Vi,
                                const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, double gravity,
                                Eigen::Vector3d& Pj, Eigen::Quaterniond& Qj, Eigen::Vector3d& Vj) const {
  Eigen::Vector3d alpha, beta;
  Eigen::Quaterniond gamma;
  corrected_deltas(ba, bg, alpha, gamma, beta);
  const Eigen::Vector3d g_w(0.0, 0.0, -gravity);
  const double T = sum_dt_;
  Pj = Pi + Vi * T + 0.5 * g_w * T * T + Qi * alpha;
  Vj = Vi + g_w * T + Qi * beta;
  Qj = (Qi * gamma).normalized();
}

ImuPreintegration::Vector15 ImuPreintegration::evaluate_residual(
    const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi, const Eigen::Vector3d& Vi, const Eigen::Vector3d& Bai,
    const Eigen::Vector3d& Bgi, const Eigen::Vector3d& Pj, const Eigen::Quaterniond& Qj, const Eigen::Vector3d& Vj,
    const Eigen::Vector3d& Baj, const Eigen::Vector3d& Bgj, double gravity) const {
  Eigen::Vector3d alpha, beta;
  Eigen::Quaterniond gamma;
  corrected_deltas(Bai, Bgi, alpha, gamma, beta);
  const Eigen::Vector3d g_w(0.0, 0.0, -gravity);
  const double T = sum_dt_;
  const Eigen::Quaterniond Qi_inv = Qi.conjugate();
  // VINS-Mono §VI-B: Pj = Pi + Vi T + ½ g T² + Ri α,  Vj = Vi + g T + Ri β,  Qj = Qi γ.
  Vector15 r;
  r.segment<3>(kP) = Qi_inv * (Pj - Pi - Vi * T - 0.5 * g_w * T * T) - alpha;
  r.segment<3>(kR) = 2.0 * (gamma.conjugate() * (Qi_inv * Qj)).vec();
  r.segment<3>(kV) = Qi_inv * (Vj - Vi - g_w * T) - beta;
  r.segment<3>(kBa) = Baj - Bai;
  r.segment<3>(kBg) = Bgj - Bgi;
  return r;
}

}  // namespace dynavins::imu
