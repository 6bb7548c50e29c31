#pragma once
// IMU measurements of a SmoothTrajectory, with ground truth.
//   specific force  a_b = R_wb^T (a_w - g_w),  g_w = (0, 0, -g)
//   angular rate    ω_b = body angular velocity of the orientation spline
// plus the noise of ImuNoiseModel. Sample k is taken at t_ns = t_first_ns + k * period_ns, with
// period_ns = round(1e9 / rate) and evaluated at t = t_ns * 1e-9 s, so timestamps and truth agree exactly.
// Sample k carries bias b_k; then b_{k+1} = b_k + σ_walk sqrt(dt) n_k (Kalibr discretisation).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "messages/sensor_messages.hpp"
#include "sim/motion/imu_noise_model.hpp"
#include "sim/motion/smooth_trajectory.hpp"

namespace dynavins::sim {

/// IMU simulation settings.
struct ImuSimulatorOptions {
  double rate_hz = 200.0;   ///< sample rate
  double gravity = 9.81;    ///< magnitude g of g_w = (0, 0, -g) [m/s^2]
  ImuNoiseModel noise;      ///< noise densities and initial biases
  uint64_t seed = 1;        ///< random seed; same seed and options give the same samples (same std library)
};

/// Output of one simulation: samples and the truth at the same timestamps (with biases).
struct ImuSimulation {
  std::vector<ImuSample> samples;
  std::vector<GroundTruthState> truth;  ///< truth[k] belongs to samples[k]; has_velocity and has_biases set
};

/// Ground truth of `traj` at t_ns (evaluated at t = t_ns * 1e-9 s): pose and velocity, no biases
/// (has_velocity = true, has_biases = false). For camera-rate ground truth.
GroundTruthState ground_truth_at(const SmoothTrajectory& traj, int64_t t_ns);

/// Generates IMU samples along a trajectory.
class ImuSimulator {
 public:
  explicit ImuSimulator(ImuSimulatorOptions options = {});

  /// The settings in use.
  const ImuSimulatorOptions& options() const { return opt_; }
  /// Sample period [ns].
  int64_t period_ns() const { return period_ns_; }

  /// Noise-free specific force and angular rate of `traj` at time t [s] (t_ns left 0).
  ImuSample ideal_sample(const SmoothTrajectory& traj, double t) const;

  /// Samples at the multiples of the period within [traj.t_min(), traj.t_max()]. Trajectories on epoch time
  /// (TumFitOptions::shift_to_zero = false) work but are evaluated to ~0.2 us only; prefer time from 0.
  ImuSimulation simulate(const SmoothTrajectory& traj) const;
  /// Samples at t_begin_ns + k * period while <= t_end_ns; the range must lie inside the trajectory.
  ImuSimulation simulate(const SmoothTrajectory& traj, int64_t t_begin_ns, int64_t t_end_ns) const;

 private:
  ImuSimulatorOptions opt_;
  int64_t period_ns_;
};

}  // namespace dynavins::sim
