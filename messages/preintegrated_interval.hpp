#pragma once
// One preintegrated IMU interval between two consecutive frames, as the IMU stage emits it
// (ImuIntervalBuilder). Plain data: the preintegration logic is stages/imu/imu_preintegration.hpp, whose
// ImuPreintegration is built from a PreintegratedDeltas and exports one (deltas()) without loss.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "messages/sensor_messages.hpp"

namespace dynavins {

/// The state of a midpoint IMU preintegration (VINS-Mono §IV-B) as plain fields: the raw samples it
/// integrated, the biases it was linearised at, the IMU noise it used, and its deltas, covariance and
/// bias Jacobian (error state [δα, δθ, δβ, δba, δbg], see imu_preintegration.hpp).
struct PreintegratedDeltas {
  std::vector<ImuSample> samples;  ///< raw samples integrated, the interval's first (interpolated) one included
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();                      ///< accelerometer bias of linearisation
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();                      ///< gyroscope bias of linearisation
  double acc_n = 0.1, gyr_n = 0.01, acc_w = 1.0e-3, gyr_w = 1.0e-4;  ///< noise in use (ImuNoiseParams)
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();                   ///< α: position delta in frame i
  Eigen::Quaterniond gamma = Eigen::Quaterniond::Identity();         ///< γ: rotation from frame j to frame i
  Eigen::Vector3d beta = Eigen::Vector3d::Zero();                    ///< β: velocity delta in frame i
  Eigen::Matrix<double, 15, 15> covariance = Eigen::Matrix<double, 15, 15>::Zero();    ///< of the error state
  Eigen::Matrix<double, 15, 15> jacobian = Eigen::Matrix<double, 15, 15>::Identity();  ///< d(err j)/d(err i)
  double sum_dt = 0.0;                                                                 ///< interval length [s]
};

/// The IMU between frame i (t_begin_ns) and frame j (t_end_ns), both ends interpolated at the frame times.
struct PreintegratedInterval {
  int64_t t_begin_ns = 0;      ///< time of frame i
  int64_t t_end_ns = 0;        ///< time of frame j
  PreintegratedDeltas preint;  ///< deltas, covariance, bias Jacobian and the raw samples used
  bool has_gap = false;        ///< two consecutive IMU samples used here are further apart than the threshold
  int64_t max_gap_ns = 0;      ///< largest spacing of consecutive raw IMU samples bracketing/inside the interval
  int num_raw_samples = 0;     ///< real IMU samples inside (t_begin, t_end], interpolated ends not counted
};

}  // namespace dynavins
