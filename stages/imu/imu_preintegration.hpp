#pragma once
// Midpoint IMU preintegration between two frames, after VINS-Mono (Qin et al., T-RO 2018, §IV-B "IMU
// Pre-integration") and its code (IntegrationBase in VINS-Mono/VINS-Fusion), with the bias Jacobian used for
// first-order bias correction as in Forster et al. ("On-Manifold Preintegration", T-RO 2017, §VI-C).
//
// Error state (15): [δα (position), δθ (rotation, right perturbation γ ⊗ Exp(δθ)), δβ (velocity), δba, δbg],
// offsets kP, kR, kV, kBa, kBg below. Time inside is int64 ns; dt of a step is the difference of timestamps.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "messages/preintegrated_interval.hpp"
#include "messages/sensor_messages.hpp"
#include "stages/imu/imu_noise_params.hpp"

namespace dynavins::imu {

/// Preintegrated IMU measurements between two instants, with covariance and bias Jacobian.
class ImuPreintegration {
 public:
  static constexpr int kP = 0, kR = 3, kV = 6, kBa = 9, kBg = 12;  ///< error-state block offsets
  using Matrix15 = Eigen::Matrix<double, 15, 15>;
  using Vector15 = Eigen::Matrix<double, 15, 1>;

  ImuPreintegration() = default;
  /// Starts an interval at `first.t_ns` with linearisation biases (ba, bg).
  ImuPreintegration(const ImuSample& first, const Eigen::Vector3d& ba, const Eigen::Vector3d& bg,
                    const ImuNoiseParams& noise);
  /// Resumes the preintegration `d` describes (as deltas() exported it): the same state, bit for bit.
  explicit ImuPreintegration(const PreintegratedDeltas& d);

  /// The whole state as plain data, for the PreintegratedInterval message.
  PreintegratedDeltas deltas() const;

  /// Adds the next sample (t_ns must be > the last one's, else std::invalid_argument) and integrates the
  /// step from the previous sample with the midpoint rule.
  void integrate(const ImuSample& s);

  /// Re-integrates all stored samples with new linearisation biases (when they moved too far for
  /// first-order correction); resets covariance and Jacobian.
  void repropagate(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg);

  /// True when |ba - linearised ba| > ba_threshold or |bg - linearised bg| > bg_threshold: the first-order
  /// correction is no longer trustworthy and repropagate() should be called.
  bool bias_moved_far(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, double ba_threshold,
                    double bg_threshold) const;

  /// Deltas corrected to first order for biases (ba, bg) (Forster §VI-C; VINS-Mono §IV-B).
  void corrected_deltas(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, Eigen::Vector3d& alpha,
                       Eigen::Quaterniond& gamma, Eigen::Vector3d& beta) const;

  /// Body state at the interval's end predicted from (Pi, Qi, Vi) at its start, deltas bias-corrected with
  /// (ba, bg) and world gravity (0, 0, -gravity) (VINS-Mono §VI-B, what evaluate_residual measures against):
  /// Pj = Pi + Vi T + ½ g T² + Ri α, Vj = Vi + g T + Ri β, Qj = Qi γ.
  void predict(const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi, const Eigen::Vector3d& Vi,
               const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, double gravity, Eigen::Vector3d& Pj,
               Eigen::Quaterniond& Qj, Eigen::Vector3d& Vj) const;

  /// The 15-dim residual between states i and j (VINS-Mono §VI-B; IntegrationBase::evaluate), with world
  /// gravity g_w = (0, 0, -gravity): [r_p, r_θ, r_v, r_ba, r_bg], deltas bias-corrected with (Bai, Bgi).
  Vector15 evaluate_residual(const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi, const Eigen::Vector3d& Vi,
                            const Eigen::Vector3d& Bai, const Eigen::Vector3d& Bgi, const Eigen::Vector3d& Pj,
                            const Eigen::Quaterniond& Qj, const Eigen::Vector3d& Vj, const Eigen::Vector3d& Baj,
                            const Eigen::Vector3d& Bgj, double gravity = 9.81) const;

  const Eigen::Vector3d& delta_p() const { return alpha_; }    ///< α: position delta in frame i
  const Eigen::Quaterniond& delta_q() const { return gamma_; } ///< γ: rotation from frame j to frame i
  const Eigen::Vector3d& delta_v() const { return beta_; }     ///< β: velocity delta in frame i
  const Matrix15& covariance() const { return covariance_; }  ///< covariance of the error state
  const Matrix15& jacobian() const { return jacobian_; }      ///< d(error state at j)/d(error state at i)
  double sum_dt() const { return sum_dt_; }                    ///< interval length [s]
  int64_t t_begin_ns() const { return t_begin_ns_; }            ///< time of the first sample
  int64_t t_end_ns() const { return samples_.empty() ? t_begin_ns_ : samples_.back().t_ns; }  ///< last sample
  const Eigen::Vector3d& linearized_ba() const { return ba_; } ///< accelerometer bias of linearisation
  const Eigen::Vector3d& linearized_bg() const { return bg_; } ///< gyroscope bias of linearisation
  const std::vector<ImuSample>& samples() const { return samples_; }  ///< raw samples, first included
  const ImuNoiseParams& noise() const { return noise_; }              ///< noise parameters in use

 private:
  void reset();
  void midpoint_step(const ImuSample& s0, const ImuSample& s1);

  std::vector<ImuSample> samples_;
  ImuNoiseParams noise_;
  Eigen::Matrix<double, 18, 18> noise_cov_ = Eigen::Matrix<double, 18, 18>::Zero();
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero(), bg_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d alpha_ = Eigen::Vector3d::Zero(), beta_ = Eigen::Vector3d::Zero();
  Eigen::Quaterniond gamma_ = Eigen::Quaterniond::Identity();
  Matrix15 covariance_ = Matrix15::Zero();
  Matrix15 jacobian_ = Matrix15::Identity();
  double sum_dt_ = 0.0;
  int64_t t_begin_ns_ = 0;
};

}  // namespace dynavins::imu
