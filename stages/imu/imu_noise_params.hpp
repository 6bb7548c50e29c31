#pragma once
// IMU noise parameters with the names and meaning of VINS-Fusion's yaml (acc_n, gyr_n, acc_w, gyr_w).
//
// How VINS-Fusion uses them (integration_base.h): the 18x18 noise covariance is diag(acc_n², gyr_n², acc_n²,
// gyr_n², acc_w², gyr_w²), mapped into the state by V, whose white-noise columns carry 0.5·dt (δθ, δβ) and
// whose bias columns carry dt. So per midpoint step Var(δβ) += 0.5·acc_n²·dt² and Var(δba) += acc_w²·dt².
// For an IMU with continuous-time (Kalibr) densities σ_a [m/s²/√Hz], σ_ba [m/s³/√Hz] sampled every dt, the
// true growth is Var(δβ) += σ_a²·dt (each sample is shared by two midpoint steps, so the midpoint model's
// independent-endpoint assumption halves it) and Var(δba) += σ_ba²·dt. Matching the two gives
// from_continuous_densities() below; the Monte Carlo test in tests/imu checks this mapping.

#include <cmath>

namespace dynavins::imu {

/// IMU noise in VINS-Fusion's yaml convention (see the file comment for the exact meaning).
struct ImuNoiseParams {
  double acc_n = 0.1;     ///< accelerometer white noise, VINS-Fusion "acc_n" (its EuRoC config values)
  double gyr_n = 0.01;    ///< gyroscope white noise, VINS-Fusion "gyr_n"
  double acc_w = 1.0e-3;  ///< accelerometer bias random walk, VINS-Fusion "acc_w"
  double gyr_w = 1.0e-4;  ///< gyroscope bias random walk, VINS-Fusion "gyr_w"

  /// Values that make VINS-Fusion's propagation reproduce, to first order, the covariance of an IMU with
  /// continuous-time densities (Kalibr convention) sampled at period dt_s:
  /// acc_n = σ_a·√(2/dt), gyr_n = σ_g·√(2/dt), acc_w = σ_ba/√dt, gyr_w = σ_bg/√dt.
  static ImuNoiseParams from_continuous_densities(double acc_noise_density, double gyr_noise_density,
                                                double acc_random_walk, double gyr_random_walk, double dt_s) {
    ImuNoiseParams p;
    p.acc_n = acc_noise_density * std::sqrt(2.0 / dt_s);
    p.gyr_n = gyr_noise_density * std::sqrt(2.0 / dt_s);
    p.acc_w = acc_random_walk / std::sqrt(dt_s);
    p.gyr_w = gyr_random_walk / std::sqrt(dt_s);
    return p;
  }
};

}  // namespace dynavins::imu
