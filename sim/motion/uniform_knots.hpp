#pragma once
// Time grid shared by the uniform cubic B-splines: segment i covers [t0 + i dt, t0 + (i+1) dt] and
// uses control points i..i+3, so N control points give N-3 segments over [t0, t0 + (N-3) dt].
// Control point k has its peak weight at the knot t0 + (k-1) dt.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dynavins::sim {

/// Knot grid of a uniform cubic B-spline with a given number of control points.
class UniformKnots {
 public:
  UniformKnots() = default;
  /// `t0`: start of the valid range [s]; `dt`: knot spacing [s] (> 0); `num_control`: >= 4.
  UniformKnots(double t0, double dt, int num_control) : t0_(t0), dt_(dt), n_(num_control) {
    if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(t0))
      throw std::invalid_argument("UniformKnots: knot spacing must be finite and > 0");
    if (num_control < 4)
      throw std::invalid_argument("UniformKnots: need at least 4 control points, got " + std::to_string(num_control));
  }

  double t0() const { return t0_; }                                ///< start of the valid range [s]
  double dt() const { return dt_; }                                ///< knot spacing [s]
  int num_control() const { return n_; }                            ///< number of control points
  int num_segments() const { return n_ - 3; }                       ///< number of polynomial pieces
  double t_min() const { return t0_; }                              ///< first valid time [s]
  double t_max() const { return t0_ + dt_ * num_segments(); }        ///< last valid time [s]
  /// Time at which control point k has its peak basis weight.
  double control_time(int k) const { return t0_ + dt_ * (k - 1); }

  /// Segment index and normalised time u in [0, 1] of time t; throws outside [t_min, t_max] (with a
  /// tolerance of 1e-9 s so that times rounded through nanoseconds at the ends still evaluate).
  void locate(double t, int& segment, double& u) const {
    const double s = (t - t0_) / dt_;
    const double tol = 1e-9 / dt_;
    if (!(s >= -tol && s <= num_segments() + tol))
      throw std::out_of_range("spline evaluated at t=" + std::to_string(t) + " s outside [" +
                              std::to_string(t_min()) + ", " + std::to_string(t_max()) + "]");
    segment = std::clamp(static_cast<int>(std::floor(s)), 0, num_segments() - 1);
    u = std::clamp(s - segment, 0.0, 1.0);
  }

 private:
  double t0_ = 0.0;
  double dt_ = 1.0;
  int n_ = 0;
};

}  // namespace dynavins::sim
