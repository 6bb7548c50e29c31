#include "eval/umeyama.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <stdexcept>
#include <string>

namespace dynavins::eval {

Similarity3 umeyama(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst, bool with_scale) {
  if (src.cols() != dst.cols()) {
    throw std::invalid_argument("umeyama: " + std::to_string(src.cols()) + " source points but " +
                                std::to_string(dst.cols()) + " destination points");
  }
  const Eigen::Index n = src.cols();
  if (n < 3) throw std::invalid_argument("umeyama: needs at least 3 point pairs, got " + std::to_string(n));

  // Means (eq. 34, 35), variance of the source (eq. 36), covariance (eq. 38).
  const Eigen::Vector3d mean_src = src.rowwise().mean();
  const Eigen::Vector3d mean_dst = dst.rowwise().mean();
  const Eigen::Matrix3Xd src_c = src.colwise() - mean_src;
  const Eigen::Matrix3Xd dst_c = dst.colwise() - mean_dst;
  const double var_src = src_c.squaredNorm() / static_cast<double>(n);
  const Eigen::Matrix3d cov = dst_c * src_c.transpose() / static_cast<double>(n);

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d d = svd.singularValues();
  // Rank < 2 (all points on a line or one point) leaves the rotation about that line undefined.
  if (!(d(1) > 1e-12 * d(0)) || var_src <= 0.0) {
    throw std::runtime_error("umeyama: points are degenerate (collinear or coincident), alignment undefined");
  }

  // S of eq. 43 flips the weakest axis when needed so that R is a rotation, not a reflection.
  Eigen::Vector3d s_diag = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s_diag(2) = -1.0;

  Similarity3 T;
  T.R = svd.matrixU() * s_diag.asDiagonal() * svd.matrixV().transpose();  // eq. 40
  T.s = with_scale ? d.dot(s_diag) / var_src : 1.0;                       // eq. 42
  T.t = mean_dst - T.s * T.R * mean_src;                                  // eq. 41
  return T;
}

}  // namespace dynavins::eval
