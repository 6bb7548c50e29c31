#include "stages/estimator/factors/reprojection_factors.hpp"

#include <Eigen/Geometry>

#include "stages/common/so3.hpp"

namespace dynavins::estimator {
namespace {

using Matrix3 = Eigen::Matrix3d;
using Vector3 = Eigen::Vector3d;
using Matrix23 = Eigen::Matrix<double, 2, 3>;
using Matrix26 = Eigen::Matrix<double, 2, 6>;

/// A pose block [p, q] read as (p, R).
struct Pose {
  Vector3 p;
  Matrix3 R;
  explicit Pose(const double* x)
      : p(Eigen::Map<const Vector3>(x)), R(Eigen::Map<const Eigen::Quaterniond>(x + 3).toRotationMatrix()) {}
};

double weight_of(const double* weight) { return weight == nullptr ? 1.0 : *weight; }

/// Writes scaled residual (P.xy / P.z − xy_obs) and returns d r / d P (on the z = 1 plane, VINS-Mono §VI-C).
Matrix23 project_residual(const Vector3& P, const Eigen::Vector2d& xy_obs, double scale, double* residuals) {
  const double inv_z = 1.0 / P.z();
  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = scale * (P.head<2>() * inv_z - xy_obs);
  Matrix23 d;
  d << inv_z, 0.0, -P.x() * inv_z * inv_z, 0.0, inv_z, -P.y() * inv_z * inv_z;
  return scale * d;
}

/// Pose-block Jacobian [δp, δθ] into the 2x7 row-major block, column 7 zero.
void write_pose(double* jacobian, const Matrix26& tangent) {
  if (jacobian == nullptr) return;
  Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobian);
  J.leftCols<6>() = tangent;
  J.col(6).setZero();
}

void write_inverse_depth(double* jacobian, const Eigen::Vector2d& d) {
  if (jacobian == nullptr) return;
  Eigen::Map<Eigen::Vector2d> J(jacobian);
  J = d;
}

/// [A B] as a 2x6 tangent Jacobian.
Matrix26 join(const Matrix23& d_dp, const Matrix23& d_dtheta) {
  Matrix26 j;
  j << d_dp, d_dtheta;
  return j;
}

}  // namespace

// Point chain (all factors): P_ci = xy1_i / λ → P_bi = R_bc0 P_ci + p_bc0 → P_w = R_i P_bi + p_i →
// P_bj = R_j^T (P_w − p_j) → P_cj = R_bck^T (P_bj − p_bck). Right perturbations R ⊗ Exp(δθ) give
// d(R x)/dδθ = −R [x]x and d(R^T x)/dδθ = [R^T x]x.

ProjectionTwoFrameOneCamFactor::ProjectionTwoFrameOneCamFactor(const Eigen::Vector2d& xy_i,
                                                               const Eigen::Vector2d& xy_j, double sqrt_info,
                                                               const double* weight)
    : xy_i_(xy_i), xy_j_(xy_j), sqrt_info_(sqrt_info), weight_(weight) {}

bool ProjectionTwoFrameOneCamFactor::Evaluate(double const* const* parameters, double* residuals,
                                              double** jacobians) const {
  const Pose Ti(parameters[0]), Tj(parameters[1]), Tbc(parameters[2]);
  const double inv_depth = parameters[3][0];
  const Vector3 xy1_i(xy_i_.x(), xy_i_.y(), 1.0);
  const Vector3 P_ci = xy1_i / inv_depth;
  const Vector3 P_bi = Tbc.R * P_ci + Tbc.p;
  const Vector3 P_w = Ti.R * P_bi + Ti.p;
  const Vector3 P_bj = Tj.R.transpose() * (P_w - Tj.p);
  const Vector3 P_cj = Tbc.R.transpose() * (P_bj - Tbc.p);
  const Matrix23 d_r = project_residual(P_cj, xy_j_, weight_of(weight_) * sqrt_info_, residuals);
  if (jacobians == nullptr) return true;

  const Matrix3 R_cb = Tbc.R.transpose();
  const Matrix3 R_cj_bi = R_cb * Tj.R.transpose() * Ti.R;  // body i → cam j
  const Matrix23 d_pw = d_r * R_cb * Tj.R.transpose();     // d r / d P_w
  if (jacobians[0] != nullptr) write_pose(jacobians[0], join(d_pw, -d_r * R_cj_bi * so3::hat(P_bi)));
  if (jacobians[1] != nullptr) write_pose(jacobians[1], join(-d_pw, d_r * R_cb * so3::hat(P_bj)));
  if (jacobians[2] != nullptr) {
    // The extrinsic enters twice: cam0 → body at i and body → cam0 at j.
    const Matrix23 d_dp = d_r * (R_cj_bi - R_cb);
    const Matrix23 d_dtheta = d_r * (-R_cj_bi * Tbc.R * so3::hat(P_ci) + so3::hat(P_cj));
    write_pose(jacobians[2], join(d_dp, d_dtheta));
  }
  write_inverse_depth(jacobians[3], d_r * R_cj_bi * Tbc.R * (-xy1_i / (inv_depth * inv_depth)));
  return true;
}

ProjectionTwoFrameTwoCamFactor::ProjectionTwoFrameTwoCamFactor(const Eigen::Vector2d& xy_i,
                                                               const Eigen::Vector2d& xy_j, double sqrt_info,
                                                               const double* weight)
    : xy_i_(xy_i), xy_j_(xy_j), sqrt_info_(sqrt_info), weight_(weight) {}

bool ProjectionTwoFrameTwoCamFactor::Evaluate(double const* const* parameters, double* residuals,
                                              double** jacobians) const {
  const Pose Ti(parameters[0]), Tj(parameters[1]), Tbc0(parameters[2]), Tbc1(parameters[3]);
  const double inv_depth = parameters[4][0];
  const Vector3 xy1_i(xy_i_.x(), xy_i_.y(), 1.0);
  const Vector3 P_ci = xy1_i / inv_depth;
  const Vector3 P_bi = Tbc0.R * P_ci + Tbc0.p;
  const Vector3 P_w = Ti.R * P_bi + Ti.p;
  const Vector3 P_bj = Tj.R.transpose() * (P_w - Tj.p);
  const Vector3 P_cj = Tbc1.R.transpose() * (P_bj - Tbc1.p);
  const Matrix23 d_r = project_residual(P_cj, xy_j_, weight_of(weight_) * sqrt_info_, residuals);
  if (jacobians == nullptr) return true;

  const Matrix3 R_c1b = Tbc1.R.transpose();
  const Matrix3 R_cj_bi = R_c1b * Tj.R.transpose() * Ti.R;  // body i → cam1 j
  const Matrix23 d_pw = d_r * R_c1b * Tj.R.transpose();     // d r / d P_w
  const Matrix23 d_pbi = d_r * R_cj_bi;                     // d r / d P_bi
  if (jacobians[0] != nullptr) write_pose(jacobians[0], join(d_pw, -d_pbi * so3::hat(P_bi)));
  if (jacobians[1] != nullptr) write_pose(jacobians[1], join(-d_pw, d_r * R_c1b * so3::hat(P_bj)));
  if (jacobians[2] != nullptr) write_pose(jacobians[2], join(d_pbi, -d_pbi * Tbc0.R * so3::hat(P_ci)));
  if (jacobians[3] != nullptr) write_pose(jacobians[3], join(-d_r * R_c1b, d_r * so3::hat(P_cj)));
  write_inverse_depth(jacobians[4], d_r * R_cj_bi * Tbc0.R * (-xy1_i / (inv_depth * inv_depth)));
  return true;
}

ProjectionOneFrameTwoCamFactor::ProjectionOneFrameTwoCamFactor(const Eigen::Vector2d& xy_i,
                                                               const Eigen::Vector2d& xy_j, double sqrt_info,
                                                               const double* weight)
    : xy_i_(xy_i), xy_j_(xy_j), sqrt_info_(sqrt_info), weight_(weight) {}

bool ProjectionOneFrameTwoCamFactor::Evaluate(double const* const* parameters, double* residuals,
                                              double** jacobians) const {
  const Pose Tbc0(parameters[0]), Tbc1(parameters[1]);
  const double inv_depth = parameters[2][0];
  const Vector3 xy1_i(xy_i_.x(), xy_i_.y(), 1.0);
  const Vector3 P_ci = xy1_i / inv_depth;
  const Vector3 P_b = Tbc0.R * P_ci + Tbc0.p;
  const Vector3 P_c1 = Tbc1.R.transpose() * (P_b - Tbc1.p);
  const Matrix23 d_r = project_residual(P_c1, xy_j_, weight_of(weight_) * sqrt_info_, residuals);
  if (jacobians == nullptr) return true;

  const Matrix3 R_c1b = Tbc1.R.transpose();
  if (jacobians[0] != nullptr) write_pose(jacobians[0], join(d_r * R_c1b, -d_r * R_c1b * Tbc0.R * so3::hat(P_ci)));
  if (jacobians[1] != nullptr) write_pose(jacobians[1], join(-d_r * R_c1b, d_r * so3::hat(P_c1)));
  write_inverse_depth(jacobians[2], d_r * R_c1b * Tbc0.R * (-xy1_i / (inv_depth * inv_depth)));
  return true;
}

}  // namespace dynavins::estimator
