#pragma once
// Least-squares rigid / similarity alignment of two point sets (Umeyama's method).

#include <Eigen/Core>

namespace dynavins::eval {

/// A similarity transform x -> s * R * x + t (s == 1 for a rigid SE(3) transform).
struct Similarity3 {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double s = 1.0;

  /// Maps one point.
  Eigen::Vector3d operator()(const Eigen::Vector3d& x) const { return s * (R * x) + t; }
};

/// R, t (and s when with_scale) minimising sum_i |dst_i - (s R src_i + t)|^2, columns are points.
/// Equations 34-43 of S. Umeyama, "Least-squares estimation of transformation parameters between
/// two point patterns", IEEE TPAMI 13(4), 1991. Throws std::invalid_argument on mismatched sizes
/// or fewer than 3 points, std::runtime_error when the points are degenerate (collinear).
Similarity3 umeyama(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst, bool with_scale);

}  // namespace dynavins::eval
