#pragma once
// Continuous-time IMU noise model (Kalibr / EuRoC convention, see github.com/ethz-asl/kalibr wiki
// "IMU Noise Model"): measurement = truth + bias + white noise, bias = random walk.
// Discretised at sample period dt:  σ_white,d = σ_white / sqrt(dt),  σ_bias_step,d = σ_walk * sqrt(dt).
// Defaults are EuRoC's ADIS16448 values (mav0/imu0/sensor.yaml).

#include <Eigen/Core>

namespace dynavins::sim {

/// IMU noise densities and initial biases.
struct ImuNoiseModel {
  double acc_noise_density = 2.0e-3;    ///< accelerometer white noise [m/s^2/sqrt(Hz)]
  double gyr_noise_density = 1.7e-4;    ///< gyroscope white noise [rad/s/sqrt(Hz)]
  double acc_random_walk = 3.0e-3;      ///< accelerometer bias random walk [m/s^3/sqrt(Hz)]
  double gyr_random_walk = 1.9e-5;      ///< gyroscope bias random walk [rad/s^2/sqrt(Hz)]
  Eigen::Vector3d acc_bias_initial = Eigen::Vector3d::Zero();  ///< accelerometer bias at the first sample [m/s^2]
  Eigen::Vector3d gyr_bias_initial = Eigen::Vector3d::Zero();  ///< gyroscope bias at the first sample [rad/s]

  /// A model with no noise, no bias walk and zero biases (the exact IMU of the trajectory).
  static ImuNoiseModel noise_free() {
    ImuNoiseModel m;
    m.acc_noise_density = m.gyr_noise_density = m.acc_random_walk = m.gyr_random_walk = 0.0;
    return m;
  }
};

}  // namespace dynavins::sim
