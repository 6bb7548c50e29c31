#include "sim/motion/trajectory_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/motion/bspline_basis.hpp"
#include "stages/common/so3.hpp"

namespace dynavins::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Symmetric block-banded normal equations: block (k, k+o), o = 0..3, of size B x B. A cubic B-spline
// couples at most four consecutive control points, so nothing lies outside this band.
template <int B>
class BandedNormalEquations {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  explicit BandedNormalEquations(int n) : n_(n), H_(n), g_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n) * B)) {
    for (auto& row : H_)
      for (auto& b : row) b.setZero();
  }
  // Adds w * J^T J and w * J^T r for a residual touching control points first..first+m-1.
  template <int R>
  void add(int first, const std::vector<Eigen::Matrix<double, R, B>>& J, const Eigen::Matrix<double, R, 1>& r,
           double w) {
    const int m = static_cast<int>(J.size());
    for (int a = 0; a < m; ++a) {
      g_.template segment<B>(static_cast<Eigen::Index>(first + a) * B) += w * J[a].transpose() * r;
      for (int b = a; b < m; ++b) H_[first + a][b - a] += w * J[a].transpose() * J[b];
    }
  }
  // Solves H x = rhs (rhs has n*B rows, any number of columns).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(static_cast<size_t>(n_) * 7 * B * B);
    for (int k = 0; k < n_; ++k)
      for (int o = 0; o < 4 && k + o < n_; ++o)
        for (int r = 0; r < B; ++r)
          for (int c = 0; c < B; ++c) {
            const double v = H_[k][o](r, c);
            if (v == 0.0) continue;
            trip.emplace_back(k * B + r, (k + o) * B + c, v);
            if (o > 0) trip.emplace_back((k + o) * B + c, k * B + r, v);
          }
    Eigen::SparseMatrix<double> H(static_cast<Eigen::Index>(n_) * B, static_cast<Eigen::Index>(n_) * B);
    H.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(H);
    if (ldlt.info() != Eigen::Success) throw std::runtime_error("fit_trajectory: normal equations are singular");
    Eigen::MatrixXd x = ldlt.solve(rhs);
    if (ldlt.info() != Eigen::Success || !x.allFinite())
      throw std::runtime_error("fit_trajectory: solving the normal equations failed");
    return x;
  }
  const Eigen::VectorXd& gradient() const { return g_; }

 private:
  int n_;
  std::vector<std::array<Block, 4>> H_;
  Eigen::VectorXd g_;
};

void validate(const std::vector<TimedPose>& poses) {
  if (poses.size() < 2) throw std::invalid_argument("fit_trajectory: need at least 2 poses, got " + std::to_string(poses.size()));
  for (size_t m = 0; m < poses.size(); ++m) {
    const TimedPose& s = poses[m];
    const std::string where = "fit_trajectory: pose " + std::to_string(m) + " (t=" + std::to_string(s.t) + "): ";
    if (!std::isfinite(s.t) || !s.p.allFinite() || !s.q.coeffs().allFinite())
      throw std::invalid_argument(where + "non-finite value");
    if (std::abs(s.q.norm() - 1.0) > 1e-3) throw std::invalid_argument(where + "quaternion is not unit");
    if (m > 0) {
      if (!(s.t > poses[m - 1].t)) throw std::invalid_argument(where + "time is not strictly increasing");
      if (poses[m - 1].q.angularDistance(s.q) > 0.9 * kPi)
        throw std::invalid_argument(where + "orientation differs from the previous one by more than 0.9 pi; "
                                            "the rotation direction is ambiguous (add samples in between)");
    }
  }
}

// Orientation of the data at time t by slerp between the bracketing samples (clamped at the ends).
Eigen::Quaterniond interpolate_orientation(const std::vector<TimedPose>& poses, double t) {
  if (t <= poses.front().t) return poses.front().q.normalized();
  if (t >= poses.back().t) return poses.back().q.normalized();
  const auto it = std::upper_bound(poses.begin(), poses.end(), t, [](double x, const TimedPose& s) { return x < s.t; });
  const TimedPose& b = *it;
  const TimedPose& a = *(it - 1);
  return a.q.normalized().slerp((t - a.t) / (b.t - a.t), b.q.normalized());
}

std::vector<Eigen::Vector3d> fit_positions(const std::vector<TimedPose>& poses, const UniformKnots& knots,
                                          const TrajectoryFitOptions& o) {
  const int n = knots.num_control();
  BandedNormalEquations<1> ne(n);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  const double w_data = 1.0 / (o.position_sigma * o.position_sigma);
  std::vector<Eigen::Matrix<double, 1, 1>> J(4);
  for (const TimedPose& s : poses) {
    int i;
    double u;
    knots.locate(s.t, i, u);
    const bspline::CubicBasis b = bspline::cubic_basis(u);
    for (int k = 0; k < 4; ++k) {
      J[k](0, 0) = b.b[k];
      rhs.row(i + k) += w_data * b.b[k] * s.p.transpose();
    }
    ne.add<1>(i, J, Eigen::Matrix<double, 1, 1>::Zero(), w_data);
  }
  // Segment i has the constant jerk (-c_i + 3c_{i+1} - 3c_{i+2} + c_{i+3}) / dt^3, so this is ∫|j|^2 dt / q_j.
  const double dt = knots.dt();
  const double w_reg = 1.0 / (o.jerk_psd * std::pow(dt, 5));
  std::vector<Eigen::Matrix<double, 1, 1>> D(4);
  D[0](0, 0) = -1.0;
  D[1](0, 0) = 3.0;
  D[2](0, 0) = -3.0;
  D[3](0, 0) = 1.0;
  for (int i = 0; i + 3 < n; ++i) ne.add<1>(i, D, Eigen::Matrix<double, 1, 1>::Zero(), w_reg);
  const Eigen::MatrixXd x = ne.solve(rhs);
  std::vector<Eigen::Vector3d> c(n);
  for (int k = 0; k < n; ++k) c[k] = x.row(k).transpose();
  return c;
}

Eigen::Vector3d angular_jerk_residual(const BSplineSO3& s, int i) {
  return s.increment(i) - 2.0 * s.increment(i + 1) + s.increment(i + 2);
}

// Gauss-Newton step for the orientation control points; returns the cost before the step in `cost`.
Eigen::VectorXd rotation_step(const std::vector<TimedPose>& poses, const BSplineSO3& spline, double w_data,
                             double w_reg, double& cost) {
  const int n = spline.knots().num_control();
  BandedNormalEquations<3> ne(n);
  cost = 0.0;
  std::array<Eigen::Matrix3d, 4> Jc;
  std::vector<Eigen::Matrix3d> J(4);
  for (const TimedPose& s : poses) {
    int first;
    const Eigen::Matrix3d R = spline.orientation_with_jacobians(s.t, first, Jc);
    const Eigen::Vector3d r = so3::log(s.q.toRotationMatrix().transpose() * R);
    const Eigen::Matrix3d Jri = so3::right_jacobian_inverse(r);
    for (int k = 0; k < 4; ++k) J[k] = Jri * Jc[k];
    ne.add<3>(first, J, r, w_data);
    cost += w_data * r.squaredNorm();
  }
  // Angular jerk of segment i ~ (d_i - 2 d_{i+1} + d_{i+2}) / dt^3, d_m = Log(R_m^T R_{m+1}) depends on
  // R_m through -Jl^-1(d_m) and on R_{m+1} through Jr^-1(d_m).
  std::vector<Eigen::Matrix3d> D(4);
  for (int i = 0; i + 3 < n; ++i) {
    const Eigen::Vector3d& d0 = spline.increment(i);
    const Eigen::Vector3d& d1 = spline.increment(i + 1);
    const Eigen::Vector3d& d2 = spline.increment(i + 2);
    const Eigen::Vector3d e = angular_jerk_residual(spline, i);
    D[0] = -so3::left_jacobian_inverse(d0);
    D[1] = so3::right_jacobian_inverse(d0) + 2.0 * so3::left_jacobian_inverse(d1);
    D[2] = -2.0 * so3::right_jacobian_inverse(d1) - so3::left_jacobian_inverse(d2);
    D[3] = so3::right_jacobian_inverse(d2);
    ne.add<3>(i, D, e, w_reg);
    cost += w_reg * e.squaredNorm();
  }
  return -ne.solve(ne.gradient());
}

double rotation_cost(const std::vector<TimedPose>& poses, const BSplineSO3& spline, double w_data, double w_reg) {
  double cost = 0.0;
  for (const TimedPose& s : poses)
    cost += w_data * so3::log(s.q.toRotationMatrix().transpose() * spline.evaluate(s.t).R).squaredNorm();
  const int n = spline.knots().num_control();
  for (int i = 0; i + 3 < n; ++i) cost += w_reg * angular_jerk_residual(spline, i).squaredNorm();
  return cost;
}

std::vector<Eigen::Matrix3d> apply_step(const std::vector<Eigen::Matrix3d>& c, const Eigen::VectorXd& dx, double scale) {
  std::vector<Eigen::Matrix3d> out(c.size());
  for (size_t k = 0; k < c.size(); ++k) {
    const Eigen::Matrix3d R = c[k] * so3::exp(scale * dx.segment<3>(static_cast<Eigen::Index>(3 * k)));
    out[k] = Eigen::Quaterniond(R).normalized().toRotationMatrix();  // keep exactly orthonormal
  }
  return out;
}

}  // namespace

SmoothTrajectory fit_trajectory(const std::vector<TimedPose>& poses, const TrajectoryFitOptions& o,
                               TrajectoryFitReport* report) {
  validate(poses);
  if (!(o.knot_spacing > 0.0) || !(o.position_sigma > 0.0) || !(o.rotation_sigma > 0.0) || !(o.jerk_psd > 0.0) ||
      !(o.angular_jerk_psd > 0.0))
    throw std::invalid_argument("fit_trajectory: knot spacing, sigmas and PSDs must be > 0");
  const double t0 = poses.front().t;
  const double span = poses.back().t - t0;
  const int segments = std::max(1, static_cast<int>(std::ceil(span / o.knot_spacing - 1e-9)));
  const double dt = span / segments;
  const UniformKnots knots(t0, dt, segments + 3);
  const int n = knots.num_control();

  BSplineR3 pos(t0, dt, fit_positions(poses, knots, o));

  std::vector<Eigen::Matrix3d> rc(n);
  for (int k = 0; k < n; ++k) rc[k] = interpolate_orientation(poses, knots.control_time(k)).toRotationMatrix();
  BSplineSO3 rot(t0, dt, rc);
  const double w_data = 1.0 / (o.rotation_sigma * o.rotation_sigma);
  const double w_reg = 1.0 / (o.angular_jerk_psd * std::pow(dt, 5));
  int iterations = 0;
  bool converged = false;
  for (; iterations < o.max_iterations && !converged; ++iterations) {
    double cost;
    const Eigen::VectorXd dx = rotation_step(poses, rot, w_data, w_reg, cost);
    // Backtracking keeps Gauss-Newton monotone if the linearisation is poor far from the optimum.
    double scale = 1.0;
    for (int ls = 0; ls < 10; ++ls, scale *= 0.5) {
      std::vector<Eigen::Matrix3d> trial = apply_step(rc, dx, scale);
      BSplineSO3 trial_spline(t0, dt, trial);
      const double new_cost = rotation_cost(poses, trial_spline, w_data, w_reg);
      if (new_cost <= cost || ls == 9) {
        rc = std::move(trial);
        rot = std::move(trial_spline);
        converged = scale * dx.lpNorm<Eigen::Infinity>() < 1e-10 || (cost - new_cost) <= 1e-12 * cost;
        break;
      }
    }
  }

  SmoothTrajectory traj(std::move(pos), std::move(rot));
  if (report) {
    TrajectoryFitReport& r = *report;
    r = TrajectoryFitReport{};
    r.num_samples = static_cast<int>(poses.size());
    r.num_control_points = n;
    r.knot_spacing = dt;
    r.gauss_newton_iterations = iterations;
    r.converged = converged;
    double sp = 0.0, sr = 0.0;
    for (const TimedPose& s : poses) {
      const KinematicState k = traj.evaluate(s.t);
      const double ep = (k.p_w - s.p).norm();
      const double er = so3::log(s.q.toRotationMatrix().transpose() * k.R_wb).norm();
      sp += ep * ep;
      sr += er * er;
      r.position_max = std::max(r.position_max, ep);
      r.rotation_max = std::max(r.rotation_max, er);
      r.max_acceleration = std::max(r.max_acceleration, k.a_w.norm());
      r.max_angular_velocity = std::max(r.max_angular_velocity, k.omega_b.norm());
    }
    r.position_rms = std::sqrt(sp / poses.size());
    r.rotation_rms = std::sqrt(sr / poses.size());
  }
  return traj;
}

}  // namespace dynavins::sim
