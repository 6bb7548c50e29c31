#pragma once
// Uniform cubic B-spline in R^3 (used for the body position). C2 everywhere; value and the first three
// time derivatives are exact polynomials (see bspline_basis.hpp for the basis).

#include <vector>

#include <Eigen/Core>

#include "sim/motion/bspline_basis.hpp"
#include "sim/motion/uniform_knots.hpp"

namespace dynavins::sim {

/// Position, velocity, acceleration and jerk of an R^3 spline at one time.
struct SplineR3Value {
  Eigen::Vector3d p, v, a, j;
};

/// Uniform cubic B-spline with values in R^3.
class BSplineR3 {
 public:
  BSplineR3() = default;
  /// Control points c_k, k = 0..N-1 (N >= 4), on the grid `t0 + k dt` (see UniformKnots).
  BSplineR3(double t0, double dt, std::vector<Eigen::Vector3d> control)
      : knots_(t0, dt, static_cast<int>(control.size())), c_(std::move(control)) {}

  const UniformKnots& knots() const { return knots_; }                ///< the knot grid
  const std::vector<Eigen::Vector3d>& control() const { return c_; }  ///< the control points

  /// Value and derivatives at t (throws std::out_of_range outside the valid range).
  SplineR3Value evaluate(double t) const {
    int i;
    double u;
    knots_.locate(t, i, u);
    const bspline::CubicBasis b = bspline::cubic_basis(u);
    const double inv = 1.0 / knots_.dt();
    SplineR3Value r{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                    Eigen::Vector3d::Zero()};
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& c = c_[i + k];
      r.p += b.b[k] * c;
      r.v += b.db[k] * c;
      r.a += b.ddb[k] * c;
      r.j += b.dddb[k] * c;
    }
    r.v *= inv;
    r.a *= inv * inv;
    r.j *= inv * inv * inv;
    return r;
  }

 private:
  UniformKnots knots_;
  std::vector<Eigen::Vector3d> c_;
};

}  // namespace dynavins::sim
