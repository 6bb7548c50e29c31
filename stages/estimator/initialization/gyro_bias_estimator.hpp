#pragma once
// Gyroscope bias calibration from visual rotations (VINS-Mono T-RO 2018 §V-B-1 "Gyroscope Bias Calibration"):
//   min_δbg Σ_k || Log( γ_{k,k+1}(bg + δbg)^-1 ⊗ q_bk^-1 ⊗ q_bk+1 ) ||²,  γ(bg + δbg) ≈ γ ⊗ Exp(J^γ_bg δbg),
// one Gauss-Newton step (linear least squares in δbg).

#include <vector>

#include <Eigen/Core>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

/// Gyroscope bias correction δbg (add it to the preintegrations' common linearisation bias).
/// R_wb[k]: body orientations of the N+1 frames in any common reference frame (e.g. from SfM);
/// preints[k]: preintegration from frame k to k+1 (size N; all with the same linearisation bias).
/// Throws std::invalid_argument on mismatched sizes; returns zero when fewer than one interval.
Eigen::Vector3d estimate_gyro_bias(const std::vector<Eigen::Matrix3d>& R_wb,
                                 const std::vector<const imu::ImuPreintegration*>& preints);

/// What the fit leaves unexplained: the RMS over the intervals of || Log(γ^-1 ⊗ q_bk^-1 ⊗ q_bk+1) − J δbg ||
/// [rad]. Small when one constant bias reconciles the visual rotations with the gyroscope; large when the
/// visual rotations are wrong (a view that moves as a whole, wrong images), which no bias can explain.
/// Same arguments as estimate_gyro_bias plus its result; 0 when there is no interval.
double gyro_bias_fit_rms_rad(const std::vector<Eigen::Matrix3d>& R_wb,
                             const std::vector<const imu::ImuPreintegration*>& preints, const Eigen::Vector3d& dbg);

}  // namespace dynavins::estimator
