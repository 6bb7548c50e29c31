#pragma once
// IMU-rate propagation of the estimator's latest NavState for the fast pose output (VINS-Fusion
// Estimator::fastPredict / updateLatestState): midpoint rule in the world frame with the state's biases.
// The propagator keeps a short history of samples so that, when the estimator hands over a newer state
// (at a frame time in the past), the samples after it are replayed and the output is current again.

#include <cstdint>
#include <deque>
#include <optional>

#include "messages/estimate_messages.hpp"
#include "messages/sensor_messages.hpp"

namespace dynavins::imu {

/// Settings of ImuPropagator.
struct ImuPropagatorOptions {
  double gravity = 9.81;            ///< g_w = (0, 0, -gravity) [m/s^2]
  int64_t history_ns = 2'000'000'000;  ///< samples kept for replay after a reset [ns]
};

/// Propagates a NavState with IMU samples.
class ImuPropagator {
 public:
  explicit ImuPropagator(ImuPropagatorOptions options = {});

  /// Hands over the estimator's state (time state.t_ns, with biases). Samples already received after
  /// state.t_ns are replayed; the measurement at state.t_ns is interpolated from the history (or, if
  /// the history does not reach back that far, the first later sample is used as its value).
  void reset(const NavState& state);

  /// Adds a sample; returns the state propagated to its time, or nothing before the first reset() or
  /// for a sample not after the previous one (counted in rejected_samples()).
  std::optional<NavState> add_imu(const ImuSample& s);

  /// Latest propagated state (nothing before the first reset()).
  std::optional<NavState> latest() const;
  /// Samples rejected for not being strictly after the previous one.
  int64_t rejected_samples() const { return rejected_; }

 private:
  void step(const ImuSample& s);

  ImuPropagatorOptions opt_;
  std::deque<ImuSample> history_;
  bool initialized_ = false;
  NavState state_;
  ImuSample last_;  // measurement at state_.t_ns
  bool have_last_ = false;
  int64_t rejected_ = 0;
};

}  // namespace dynavins::imu
