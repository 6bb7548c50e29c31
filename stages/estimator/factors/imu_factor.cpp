#include "stages/estimator/factors/imu_factor.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "stages/common/so3.hpp"

namespace dynavins::estimator {
namespace {

using Matrix4 = Eigen::Matrix4d;
using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
using Ip = imu::ImuPreintegration;

// Quaternion product as matrices on [w, x, y, z]: q ⊗ p = left(q) p = right(p) q (Sola, "Quaternion
// kinematics for the error-state Kalman filter", 2017, eqs. (17)-(19)).
Matrix4 quat_left(const Quat& q) {
  Matrix4 m;
  m(0, 0) = q.w();
  m.block<1, 3>(0, 1) = -q.vec().transpose();
  m.block<3, 1>(1, 0) = q.vec();
  m.block<3, 3>(1, 1) = q.w() * Matrix3::Identity() + so3::hat(q.vec());
  return m;
}

Matrix4 quat_right(const Quat& p) {
  Matrix4 m;
  m(0, 0) = p.w();
  m.block<1, 3>(0, 1) = -p.vec().transpose();
  m.block<3, 1>(1, 0) = p.vec();
  m.block<3, 3>(1, 1) = p.w() * Matrix3::Identity() - so3::hat(p.vec());
  return m;
}

}  // namespace

ImuFactor::ImuFactor(const imu::ImuPreintegration* preintegration, double gravity)
    : preintegration_(preintegration), gravity_(gravity) {}

Eigen::Matrix<double, 15, 15> ImuFactor::sqrt_information(const imu::ImuPreintegration::Matrix15& covariance) {
  Ip::Matrix15 information = covariance.inverse();
  information = 0.5 * (information + information.transpose());  // LLT reads one triangle; keep both equal
  // P^-1 = L L^T, so S = L^T gives S^T S = P^-1.
  return Eigen::LLT<Ip::Matrix15>(information).matrixL().transpose();
}

Eigen::Matrix<double, 15, 15> ImuFactor::whitening(const imu::ImuPreintegration::Matrix15& covariance) const {
  // A solve evaluates the factor many times with the same preintegration: invert and factor once.
  std::lock_guard<std::mutex> lock(cache_mutex_);
  if (!cache_valid_ || covariance != cached_covariance_) {
    cached_covariance_ = covariance;
    cached_sqrt_information_ = sqrt_information(covariance);
    cache_valid_ = true;
  }
  return cached_sqrt_information_;
}

bool ImuFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Ip& pre = *preintegration_;
  const Eigen::Map<const Vector3> Pi(parameters[0]), Vi(parameters[1]), Bai(parameters[1] + 3),
      Bgi(parameters[1] + 6), Pj(parameters[2]), Vj(parameters[3]), Baj(parameters[3] + 3), Bgj(parameters[3] + 6);
  const Quat Qi(Eigen::Map<const Quat>(parameters[0] + 3)), Qj(Eigen::Map<const Quat>(parameters[2] + 3));

  const Ip::Vector15 e = pre.evaluate_residual(Pi, Qi, Vi, Bai, Bgi, Pj, Qj, Vj, Baj, Bgj, gravity_);
  const Ip::Matrix15 S = whitening(pre.covariance());
  Eigen::Map<Ip::Vector15> r(residuals);
  r = S * e;
  if (jacobians == nullptr) return true;

  // Quantities shared by the Jacobians (VINS-Mono §VI-B, IMUFactor::Evaluate).
  const double T = pre.sum_dt();
  const Vector3 g_w(0.0, 0.0, -gravity_);
  const Matrix3 RiT = Qi.toRotationMatrix().transpose();
  const Ip::Matrix15& J = pre.jacobian();
  const Matrix3 dp_dba = J.block<3, 3>(Ip::kP, Ip::kBa), dp_dbg = J.block<3, 3>(Ip::kP, Ip::kBg);
  const Matrix3 dq_dbg = J.block<3, 3>(Ip::kR, Ip::kBg);
  const Matrix3 dv_dba = J.block<3, 3>(Ip::kV, Ip::kBa), dv_dbg = J.block<3, 3>(Ip::kV, Ip::kBg);
  // Bias-corrected γ = γ̄ ⊗ Exp(φ), φ = J_q_bg (bg_i - b̄g), as in ImuPreintegration::corrected_deltas.
  const Vector3 phi = dq_dbg * (Bgi - pre.linearized_bg());
  const Quat gamma = (pre.delta_q() * Quat(so3::exp(phi))).normalized();
  const Quat rot_err = gamma.conjugate() * (Qi.conjugate() * Qj);  // r_θ = 2 vec(rot_err)

  // r_θ = 2 vec(A ⊗ δq ⊗ B) with δq = [1, ±δ/2] is linear in δq through left(A) right(B); its vector rows
  // give d r_θ / d δ directly.
  if (jacobians[0] != nullptr) {  // pose i
    Eigen::Matrix<double, 15, 6> Jt = Eigen::Matrix<double, 15, 6>::Zero();
    Jt.block<3, 3>(Ip::kP, 0) = -RiT;
    Jt.block<3, 3>(Ip::kP, 3) = so3::hat(RiT * (Pj - Pi - Vi * T - 0.5 * g_w * T * T));
    // Qi ⊗ Exp(δθ) → Qi^-1 gets Exp(-δθ) on its left: rot_err = γ^-1 ⊗ δq(-δθ) ⊗ Qi^-1 Qj.
    Jt.block<3, 3>(Ip::kR, 3) =
        -(quat_left(gamma.conjugate()) * quat_right(Qi.conjugate() * Qj)).bottomRightCorner<3, 3>();
    Jt.block<3, 3>(Ip::kV, 3) = so3::hat(RiT * (Vj - Vi - g_w * T));
    Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> Jm(jacobians[0]);
    Jm.leftCols<6>() = S * Jt;
    Jm.col(6).setZero();
  }
  if (jacobians[1] != nullptr) {  // speed-bias i
    Eigen::Matrix<double, 15, 9> Jt = Eigen::Matrix<double, 15, 9>::Zero();
    Jt.block<3, 3>(Ip::kP, 0) = -RiT * T;
    Jt.block<3, 3>(Ip::kP, 3) = -dp_dba;
    Jt.block<3, 3>(Ip::kP, 6) = -dp_dbg;
    // bg_i + ε: Exp(φ + J ε) = Exp(φ) Exp(Jr(φ) J ε) (so3.hpp), so γ^-1 gets Exp(-Jr J ε) on its left.
    Jt.block<3, 3>(Ip::kR, 6) =
        -quat_right(rot_err).bottomRightCorner<3, 3>() * so3::right_jacobian(phi) * dq_dbg;
    Jt.block<3, 3>(Ip::kV, 0) = -RiT;
    Jt.block<3, 3>(Ip::kV, 3) = -dv_dba;
    Jt.block<3, 3>(Ip::kV, 6) = -dv_dbg;
    Jt.block<3, 3>(Ip::kBa, 3) = -Matrix3::Identity();
    Jt.block<3, 3>(Ip::kBg, 6) = -Matrix3::Identity();
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Jm(jacobians[1]);
    Jm = S * Jt;
  }
  if (jacobians[2] != nullptr) {  // pose j
    Eigen::Matrix<double, 15, 6> Jt = Eigen::Matrix<double, 15, 6>::Zero();
    Jt.block<3, 3>(Ip::kP, 0) = RiT;
    // Qj ⊗ Exp(δθ): rot_err ⊗ δq(δθ).
    Jt.block<3, 3>(Ip::kR, 3) = quat_left(rot_err).bottomRightCorner<3, 3>();
    Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> Jm(jacobians[2]);
    Jm.leftCols<6>() = S * Jt;
    Jm.col(6).setZero();
  }
  if (jacobians[3] != nullptr) {  // speed-bias j
    Eigen::Matrix<double, 15, 9> Jt = Eigen::Matrix<double, 15, 9>::Zero();
    Jt.block<3, 3>(Ip::kV, 0) = RiT;
    Jt.block<3, 3>(Ip::kBa, 3) = Matrix3::Identity();
    Jt.block<3, 3>(Ip::kBg, 6) = Matrix3::Identity();
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Jm(jacobians[3]);
    Jm = S * Jt;
  }
  return true;
}

}  // namespace dynavins::estimator
