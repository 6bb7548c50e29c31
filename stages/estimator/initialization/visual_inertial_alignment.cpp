#include "stages/estimator/initialization/visual_inertial_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace dynavins::estimator {
namespace {

// The scale column is divided by this so its entries are comparable to the others (as VINS does);
// the unknown solved for is then kScaleConditioning * s.
constexpr double kScaleConditioning = 100.0;

// Normal equations of the stacked system, state [v^b0 .. v^bN (3 each), g-part (gdim), s (1)].
// g_fixed: gravity at which the 2-parameter refinement is linearised (ignored when basis is null).
struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  double ztz = 0.0;  ///< squared norm of the stacked right-hand side
  int rows = 0;      ///< stacked equations
};

LinearSystem build_system(const std::vector<Eigen::Matrix3d>& R, const std::vector<Eigen::Vector3d>& p,
                         const std::vector<const imu::ImuPreintegration*>& preints, const Eigen::Vector3d& p_bc,
                         const Eigen::Vector3d* g0, const Eigen::Matrix<double, 3, 2>* basis) {
  const int frames = static_cast<int>(R.size());
  const int gdim = basis ? 2 : 3;
  const int n = 3 * frames + gdim + 1;
  LinearSystem sys{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
  for (int k = 0; k + 1 < frames; ++k) {
    const imu::ImuPreintegration& pre = *preints[k];
    const double dt = pre.sum_dt();
    const Eigen::Matrix3d Rk_t = R[k].transpose();
    const Eigen::Matrix3d R_rel = Rk_t * R[k + 1];
    // Local block over [v^bk, v^bk+1, g (3), s]; gravity mapped through the basis below.
    Eigen::Matrix<double, 6, 10> H = Eigen::Matrix<double, 6, 10>::Zero();
    Eigen::Matrix<double, 6, 1> z;
    H.block<3, 3>(0, 0) = -dt * Eigen::Matrix3d::Identity();
    H.block<3, 3>(0, 6) = -0.5 * dt * dt * Rk_t;
    H.block<3, 1>(0, 9) = Rk_t * (p[k + 1] - p[k]) / kScaleConditioning;
    z.head<3>() = pre.delta_p() - p_bc + R_rel * p_bc;
    H.block<3, 3>(3, 0) = -Eigen::Matrix3d::Identity();
    H.block<3, 3>(3, 3) = R_rel;
    H.block<3, 3>(3, 6) = -dt * Rk_t;
    z.tail<3>() = pre.delta_v();
    // Reduce gravity to the refinement's 2 tangent parameters: g = g0 + B w.
    Eigen::MatrixXd Hk(6, 6 + gdim + 1);
    Hk.leftCols<6>() = H.leftCols<6>();
    if (basis) {
      Hk.middleCols(6, 2) = H.block<6, 3>(0, 6) * (*basis);
      z -= H.block<6, 3>(0, 6) * (*g0);
    } else {
      Hk.middleCols(6, 3) = H.block<6, 3>(0, 6);
    }
    Hk.rightCols<1>() = H.col(9);
    // Unit weights (VINS uses identity × 1000, which does not change the solution).
    const Eigen::MatrixXd HtH = Hk.transpose() * Hk;
    const Eigen::VectorXd Htz = Hk.transpose() * z;
    sys.A.block(3 * k, 3 * k, 6, 6) += HtH.topLeftCorner(6, 6);
    sys.A.block(3 * frames, 3 * frames, gdim + 1, gdim + 1) += HtH.bottomRightCorner(gdim + 1, gdim + 1);
    sys.A.block(3 * k, 3 * frames, 6, gdim + 1) += HtH.topRightCorner(6, gdim + 1);
    sys.A.block(3 * frames, 3 * k, gdim + 1, 6) += HtH.bottomLeftCorner(gdim + 1, 6);
    sys.b.segment(3 * k, 6) += Htz.head(6);
    sys.b.tail(gdim + 1) += Htz.tail(gdim + 1);
    sys.ztz += z.squaredNorm();
    sys.rows += 6;
  }
  return sys;
}

}  // namespace

double accelerometer_excitation(const std::vector<Eigen::Matrix3d>& R_c0_b,
                               const std::vector<const imu::ImuPreintegration*>& preints) {
  std::vector<Eigen::Vector3d> f;
  for (size_t k = 0; k < preints.size() && k < R_c0_b.size(); ++k)
    if (preints[k]->sum_dt() > 0.0) f.push_back(R_c0_b[k] * preints[k]->delta_v() / preints[k]->sum_dt());
  if (f.size() < 2) return 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& x : f) mean += x;
  mean /= static_cast<double>(f.size());
  double ss = 0.0;
  for (const Eigen::Vector3d& x : f) ss += (x - mean).squaredNorm();
  return std::sqrt(ss / static_cast<double>(f.size()));
}

Eigen::Matrix<double, 3, 2> gravity_tangent_basis(const Eigen::Vector3d& g) {
  const Eigen::Vector3d a = g.normalized();
  // Any axis not parallel to g seeds the basis.
  Eigen::Vector3d seed = std::abs(a.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d b1 = (seed - a * a.dot(seed)).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = b1;
  B.col(1) = a.cross(b1);
  return B;
}

VisualInertialAlignment align_visual_inertial(const std::vector<Eigen::Matrix3d>& R_c0_b,
                                            const std::vector<Eigen::Vector3d>& p_c0_c,
                                            const std::vector<const imu::ImuPreintegration*>& preints,
                                            const Eigen::Vector3d& p_bc,
                                            const VisualInertialAlignmentOptions& o) {
  if (R_c0_b.size() != p_c0_c.size() || preints.size() + 1 != R_c0_b.size())
    throw std::invalid_argument("align_visual_inertial: need N+1 poses and N preintegrations");
  for (const imu::ImuPreintegration* p : preints)
    if (p == nullptr) throw std::invalid_argument("align_visual_inertial: null preintegration");
  VisualInertialAlignment res;
  const int frames = static_cast<int>(R_c0_b.size());
  if (frames < 3) {
    res.reason = "alignment needs at least 3 frames";
    return res;
  }

  res.excitation = accelerometer_excitation(R_c0_b, preints);
  if (o.min_excitation > 0.0 && !(res.excitation >= o.min_excitation)) {
    res.reason = "alignment: accelerometer excitation " + std::to_string(res.excitation) + " m/s^2 (need " +
                 std::to_string(o.min_excitation) + "): the acceleration barely varies across the window, so the "
                 "scale is not observable";
    return res;
  }

  // §V-B-2: free gravity, stacked over all consecutive pairs, solved by least squares.
  const LinearSystem free = build_system(R_c0_b, p_c0_c, preints, p_bc, nullptr, nullptr);
  const Eigen::VectorXd x = free.A.ldlt().solve(free.b);
  const double s_free = x(3 * frames + 3) / kScaleConditioning;
  Eigen::Vector3d g = x.segment<3>(3 * frames);
  res.free_gravity_norm = g.norm();
  if (!x.allFinite()) {
    res.reason = "alignment: linear system is singular";
    return res;
  }
  if (std::abs(g.norm() - o.gravity_norm) > o.max_gravity_norm_error || !(s_free > 0.0)) {
    res.reason = "alignment: free solution has |g| = " + std::to_string(g.norm()) + " m/s^2 (expected " +
                 std::to_string(o.gravity_norm) + "), scale " + std::to_string(s_free);
    return res;
  }

  // §V-B-3: g = |g| ĝ0 + B w, w solved with the rest, ĝ re-normalised; a few iterations.
  Eigen::VectorXd xr = x;
  g = o.gravity_norm * g.normalized();
  LinearSystem sys;
  for (int it = 0; it < o.refinement_iterations; ++it) {
    const Eigen::Matrix<double, 3, 2> B = gravity_tangent_basis(g);
    sys = build_system(R_c0_b, p_c0_c, preints, p_bc, &g, &B);
    xr = sys.A.ldlt().solve(sys.b);
    g = o.gravity_norm * (g + B * xr.segment<2>(3 * frames)).normalized();
  }
  const int is = 3 * frames + 2;
  const double s = xr(is) / kScaleConditioning;
  if (!xr.allFinite() || !(s > 0.0)) {
    res.reason = "alignment: refined scale " + std::to_string(s) + " not positive";
    return res;
  }
  // Standard deviation of the scale from the last linear solve: residual variance times the scale's
  // diagonal entry of the inverse normal matrix (both in the conditioned unknown, so the ratio is s's).
  const int dof = sys.rows - static_cast<int>(xr.size());
  if (sys.rows > 0 && dof > 0) {
    const double rss = std::max(0.0, sys.ztz - xr.dot(sys.b));
    Eigen::VectorXd e = Eigen::VectorXd::Zero(xr.size());
    e(is) = 1.0;
    const double inv_ss = sys.A.ldlt().solve(e)(is);
    res.scale_relative_std = std::sqrt(std::max(0.0, rss / dof * inv_ss)) / xr(is);
  }
  if (o.max_scale_relative_std > 0.0 && !(res.scale_relative_std <= o.max_scale_relative_std)) {
    res.reason = "alignment: scale " + std::to_string(s) + " too uncertain (relative std " +
                 std::to_string(res.scale_relative_std) + ", need below " +
                 std::to_string(o.max_scale_relative_std) + "): not enough accelerometer excitation";
    return res;
  }
  res.success = true;
  res.scale = s;
  res.g_c0 = g;
  for (int k = 0; k < frames; ++k) res.v_b.push_back(xr.segment<3>(3 * k));
  return res;
}

}  // namespace dynavins::estimator
