#pragma once
// Test helper for the estimator's cost functions: central differences taken in the tangent space of each
// block (PoseManifold::Plus for pose blocks, additive for the others), analytic Jacobians checked against
// them, and the weight / null-Jacobian conventions of parameter_layout.hpp.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/estimator/pose_manifold.hpp"

namespace dynavins::estimator::test {

enum class Block { Pose, Euclidean };

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Residual and full-size (ambient) Jacobians of `f` at `params`.
struct Evaluation {
  Eigen::VectorXd residual;
  std::vector<RowMajorMatrix> jacobians;
};

/// Values of a cost's parameter blocks, one vector per block.
using BlockValues = std::vector<std::vector<double>>;
/// A residual as a function of its parameter blocks' values.
using ResidualFunction = std::function<Eigen::VectorXd(const BlockValues&)>;

/// Evaluates `f` at `params`. Every Jacobian starts filled with 99 (Ceres does not clear them either), so
/// a factor must write each entry itself, column 7 of a pose block included.
inline Evaluation evaluate(const ceres::CostFunction& f, const BlockValues& params,
                           const std::vector<bool>& want_jacobian = {}) {
  const int m = f.num_residuals();
  Evaluation e;
  e.residual.resize(m);
  std::vector<const double*> ptrs;
  std::vector<double*> jac_ptrs;
  for (size_t b = 0; b < params.size(); ++b) {
    ptrs.push_back(params[b].data());
    e.jacobians.emplace_back(RowMajorMatrix::Constant(m, static_cast<int>(params[b].size()), 99.0));
    const bool want = want_jacobian.empty() || want_jacobian[b];
    jac_ptrs.push_back(want ? e.jacobians.back().data() : nullptr);
  }
  REQUIRE(f.Evaluate(ptrs.data(), e.residual.data(), jac_ptrs.data()));
  return e;
}

/// Central differences of `residual` at `params` along the tangent space of block `b`: a pose block is
/// perturbed through PoseManifold::Plus (6 columns), any other additively (one column per entry).
inline RowMajorMatrix numeric_tangent_jacobian(const ResidualFunction& residual, const BlockValues& params, size_t b,
                                             Block kind, double step = 1e-6) {
  const bool pose = kind == Block::Pose;
  const int dim = pose ? 6 : static_cast<int>(params[b].size());
  const PoseManifold manifold;
  RowMajorMatrix numeric;
  for (int k = 0; k < dim; ++k) {
    BlockValues plus = params, minus = params;
    if (pose) {
      double delta[6] = {0, 0, 0, 0, 0, 0};
      delta[k] = step;
      manifold.Plus(params[b].data(), delta, plus[b].data());
      delta[k] = -step;
      manifold.Plus(params[b].data(), delta, minus[b].data());
    } else {
      plus[b][k] += step;
      minus[b][k] -= step;
    }
    const Eigen::VectorXd column = (residual(plus) - residual(minus)) / (2.0 * step);
    if (k == 0) numeric.resize(column.size(), dim);
    numeric.col(k) = column;
  }
  return numeric;
}

/// Checks, per block, max |analytic - numeric| <= tol * max(1, max |numeric|), both Jacobians first multiplied
/// on the left by `row_transform` when it is not empty (e.g. the inverse of a whitening matrix, so that rows of
/// very different scale are compared at their natural size). Also requires column 7 of a pose block to be
/// zero, and a null Jacobian pointer to leave residual and the other blocks unchanged.
inline void require_jacobians_match_numeric(const ceres::CostFunction& f,
                                         const std::vector<std::vector<double>>& params,
                                         const std::vector<Block>& kinds,
                                         const Eigen::MatrixXd& row_transform = {}, double step = 1e-6,
                                         double tol = 1e-6) {
  REQUIRE(params.size() == kinds.size());
  const Evaluation analytic = evaluate(f, params);
  const ResidualFunction residual = [&f](const BlockValues& x) {
    return Eigen::VectorXd(evaluate(f, x, std::vector<bool>(x.size(), false)).residual);
  };
  for (size_t b = 0; b < params.size(); ++b) {
    const bool pose = kinds[b] == Block::Pose;
    const int dim = pose ? 6 : static_cast<int>(params[b].size());
    RowMajorMatrix numeric = numeric_tangent_jacobian(residual, params, b, kinds[b], step);
    RowMajorMatrix a = analytic.jacobians[b].leftCols(dim);
    if (row_transform.size() > 0) {
      a = row_transform * a;
      numeric = row_transform * numeric;
    }
    const double scale = std::max(1.0, numeric.cwiseAbs().maxCoeff());
    const double error = (a - numeric).cwiseAbs().maxCoeff() / scale;
    INFO("block " << b << " relative error " << error << " (scale " << scale << ")\nanalytic\n"
                  << a << "\nnumeric\n" << numeric);
    CHECK(error < tol);
    if (pose) CHECK(analytic.jacobians[b].col(6).cwiseAbs().maxCoeff() == 0.0);
  }
  // Null Jacobian pointers (constant blocks) are skipped; the others are unchanged.
  for (size_t skip = 0; skip < params.size(); ++skip) {
    std::vector<bool> want(params.size(), true);
    want[skip] = false;
    const Evaluation partial = evaluate(f, params, want);
    CHECK((partial.residual - analytic.residual).cwiseAbs().maxCoeff() == 0.0);
    for (size_t b = 0; b < params.size(); ++b)
      if (b != skip) CHECK((partial.jacobians[b] - analytic.jacobians[b]).cwiseAbs().maxCoeff() == 0.0);
  }
}

/// A pose block [p, q xyzw] from a position and rotation.
inline std::vector<double> pose_block(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()};
}

}  // namespace dynavins::estimator::test
