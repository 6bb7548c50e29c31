#pragma once
// Ceres manifold of a pose block [p (3), q (x y z w)]: Plus is (p + δp, q ⊗ Exp(δθ)), Minus its inverse.
// Plus/MinusJacobian are the "lifted identity" [I6; 0] / [I6 0]: every factor of the estimator writes its
// pose Jacobians directly in tangent coordinates (see parameter_layout.hpp), as VINS-Fusion does.

#include <ceres/manifold.h>

namespace dynavins::estimator {

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace dynavins::estimator
