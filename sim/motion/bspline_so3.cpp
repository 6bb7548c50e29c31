#include "sim/motion/bspline_so3.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/motion/bspline_basis.hpp"
#include "stages/common/so3.hpp"

namespace dynavins::sim {

BSplineSO3::BSplineSO3(double t0, double dt, std::vector<Eigen::Matrix3d> control)
    : knots_(t0, dt, static_cast<int>(control.size())), c_(std::move(control)) {
  d_.reserve(c_.size() - 1);
  for (size_t k = 0; k + 1 < c_.size(); ++k) {
    d_.push_back(so3::log(c_[k].transpose() * c_[k + 1]));
    // Near pi the shortest-path increment flips sign discontinuously; refuse rather than mislead.
    if (d_.back().norm() > 3.0)
      throw std::invalid_argument("BSplineSO3: control rotations " + std::to_string(k) + " and " +
                                  std::to_string(k + 1) + " differ by more than 3 rad; use a smaller knot spacing");
  }
}

SplineSO3Value BSplineSO3::evaluate(double t) const {
  int i;
  double u;
  knots_.locate(t, i, u);
  const bspline::CumulativeBasis lb = bspline::cumulative_basis(u);
  Eigen::Matrix3d R = c_[i];
  Eigen::Vector3d w = Eigen::Vector3d::Zero();  // in units of 1/u
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // in units of 1/u^2
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d& d = d_[i + j];
    const Eigen::Matrix3d A = so3::exp(lb.l[j] * d);
    const Eigen::Matrix3d At = A.transpose();
    const Eigen::Vector3d w_rot = At * w;
    const Eigen::Vector3d dw = lb.dl[j] * d;
    a = At * a + w_rot.cross(dw) + lb.ddl[j] * d;
    w = w_rot + dw;
    R = R * A;
  }
  const double inv = 1.0 / knots_.dt();
  return {R, w * inv, a * inv * inv};
}

Eigen::Matrix3d BSplineSO3::orientation_with_jacobians(double t, int& first, std::array<Eigen::Matrix3d, 4>& J) const {
  int i;
  double u;
  knots_.locate(t, i, u);
  first = i;
  const bspline::CumulativeBasis lb = bspline::cumulative_basis(u);
  std::array<Eigen::Matrix3d, 3> A;
  for (int j = 0; j < 3; ++j) A[j] = so3::exp(lb.l[j] * d_[i + j]);
  // Suffix products S_j = (A_{j+1} ... A_3)^T move a perturbation inserted after factor j to the right end.
  std::array<Eigen::Matrix3d, 4> S;
  S[3].setIdentity();
  for (int j = 2; j >= 0; --j) S[j] = S[j + 1] * A[j].transpose();
  // R_i Exp(δ_i) contributes S_0 δ_i. Factor j (1-based) sees its increment move by
  // δd_j = Jr^-1(d_j) δ_{i+j} - Jl^-1(d_j) δ_{i+j-1}, and Exp(λ(d + δd)) = Exp(λ d) Exp(λ Jr(λ d) δd).
  J[0] = S[0];
  for (int k = 1; k < 4; ++k) J[k].setZero();
  for (int j = 1; j <= 3; ++j) {
    const Eigen::Vector3d& d = d_[i + j - 1];
    const double l = lb.l[j - 1];
    const Eigen::Matrix3d E = S[j] * (l * so3::right_jacobian(l * d));
    J[j] += E * so3::right_jacobian_inverse(d);
    J[j - 1] -= E * so3::left_jacobian_inverse(d);
  }
  return c_[i] * A[0] * A[1] * A[2];
}

}  // namespace dynavins::sim
