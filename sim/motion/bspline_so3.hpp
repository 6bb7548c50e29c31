#pragma once
// Cumulative uniform cubic B-spline on SO(3) (used for the body orientation R_world_body).
//   R(t) = R_i * prod_{j=1..3} Exp(λ_j(u) d_j),   d_j = Log(R_{i+j-1}^T R_{i+j})
// Lovegrove et al., "Spline Fusion" (BMVC 2013), eq. (4). The curve is C2 on SO(3): angular velocity
// and angular acceleration are continuous. Body-frame derivatives follow the recursion of Sommer et al.,
// "Efficient Derivative Computation for Cumulative B-Splines on Lie Groups" (CVPR 2020), eqs. (15), (17):
//   ω_j = A_j^T ω_{j-1} + λ'_j d_j,   α_j = A_j^T α_{j-1} + (A_j^T ω_{j-1}) x (λ'_j d_j) + λ''_j d_j,
// with A_j = Exp(λ_j d_j), ω_0 = α_0 = 0, derivatives w.r.t. u divided by dt resp. dt^2.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "sim/motion/uniform_knots.hpp"

namespace dynavins::sim {

/// Orientation and its body-frame derivatives at one time.
struct SplineSO3Value {
  Eigen::Matrix3d R;      ///< R_world_body
  Eigen::Vector3d omega;  ///< body angular velocity [rad/s]: Rdot = R [ω]x
  Eigen::Vector3d alpha;  ///< body angular acceleration [rad/s^2] (d/dt of ω)
};

/// Cumulative uniform cubic B-spline on SO(3).
class BSplineSO3 {
 public:
  BSplineSO3() = default;
  /// Control rotations R_k, k = 0..N-1 (N >= 4), on the grid of UniformKnots(t0, dt, N).
  /// Consecutive control rotations must differ by less than pi (they do for any sane knot spacing).
  BSplineSO3(double t0, double dt, std::vector<Eigen::Matrix3d> control);

  const UniformKnots& knots() const { return knots_; }                ///< the knot grid
  const std::vector<Eigen::Matrix3d>& control() const { return c_; }  ///< the control rotations

  /// Orientation, angular velocity and angular acceleration at t (throws outside the valid range).
  SplineSO3Value evaluate(double t) const;

  /// Orientation at t and the Jacobians of its right perturbation w.r.t. right perturbations of the four
  /// active control points: R(t; R_k Exp(δ_k)) ≈ R(t) Exp(Σ_j J[j] δ_{first+j}). For the fit.
  Eigen::Matrix3d orientation_with_jacobians(double t, int& first, std::array<Eigen::Matrix3d, 4>& J) const;

  /// Increment d_k = Log(R_k^T R_{k+1}) between consecutive control points (k = 0..N-2).
  const Eigen::Vector3d& increment(int k) const { return d_[k]; }

 private:
  UniformKnots knots_;
  std::vector<Eigen::Matrix3d> c_;
  std::vector<Eigen::Vector3d> d_;
};

}  // namespace dynavins::sim
