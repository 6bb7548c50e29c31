// 4-DoF pose graph with Ceres (see pose_graph_4dof.hpp). Cost functors are autodiff, in the style of
// Ceres' pose_graph_2d/3d examples and VINS-Fusion's FourDOFError.
#include "stages/loop/graph/pose_graph_4dof.hpp"

#include <cmath>
#include <memory>

#include <ceres/ceres.h>

namespace dynavins::loop {

namespace {

template <typename T>
T normalize_angle_t(const T& a) {
  constexpr double kPi = 3.14159265358979323846;
  return a - T(2.0 * kPi) * ceres::floor((a + T(kPi)) / T(2.0 * kPi));
}

/// Yaw parameter on the circle: x ⊞ δ = normalize(x + δ) (Ceres examples' AngleManifold). Plus and
/// Minus are the names ceres::AutoDiffManifold calls (a library-fixed interface, CONTRIBUTING.md).
struct AnglePlus {
  template <typename T>
  bool Plus(  // NOLINT(readability-identifier-naming)
      const T* x, const T* delta, T* x_plus_delta) const {
    x_plus_delta[0] = normalize_angle_t(x[0] + delta[0]);
    return true;
  }
  template <typename T>
  bool Minus(  // NOLINT(readability-identifier-naming)
      const T* y, const T* x, T* y_minus_x) const {
    y_minus_x[0] = normalize_angle_t(y[0] - x[0]);
    return true;
  }
};

/// R_i^T v with R_i = Rz(yaw) Ry(pitch) Rx(roll), pitch and roll constants.
template <typename T>
void rotate_to_body(const T& yaw, double pitch, double roll, const T* v, T* out) {
  // R^T = Rx(roll)^T Ry(pitch)^T Rz(yaw)^T applied right to left.
  const T cy = ceres::cos(yaw), sy = ceres::sin(yaw);
  const T a0 = cy * v[0] + sy * v[1];
  const T a1 = -sy * v[0] + cy * v[1];
  const T a2 = v[2];
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const T b0 = cp * a0 - sp * a2;
  const T b1 = a1;
  const T b2 = sp * a0 + cp * a2;
  const double cr = std::cos(roll), sr = std::sin(roll);
  out[0] = b0;
  out[1] = cr * b1 + sr * b2;
  out[2] = -sr * b1 + cr * b2;
}

/// Residual of a relative 4-DoF measurement between nodes i and j (eq. 15's r(T_j^i, T)), whitened and
/// scaled: scale * ([R_i^T (p_j - p_i) - t_ij] / sigma_t, normalize(yaw_j - yaw_i - yaw_ij) / sigma_yaw).
struct RelativePoseError {
  Eigen::Vector3d t_ij;
  double yaw_ij, pitch_i, roll_i, sigma_t, sigma_yaw, scale;

  template <typename T>
  bool operator()(const T* p_i, const T* yaw_i, const T* p_j, const T* yaw_j, T* r) const {
    const T d[3] = {p_j[0] - p_i[0], p_j[1] - p_i[1], p_j[2] - p_i[2]};
    T d_i[3];
    rotate_to_body(yaw_i[0], pitch_i, roll_i, d, d_i);
    for (int a = 0; a < 3; ++a) r[a] = T(scale) * (d_i[a] - T(t_ij[a])) / T(sigma_t);
    r[3] = T(scale) * normalize_angle_t(yaw_j[0] - yaw_i[0] - T(yaw_ij)) / T(sigma_yaw);
    return true;
  }
};

/// The same, multiplied by a switch variable s (switchable constraints).
struct SwitchedPoseError {
  RelativePoseError e;
  template <typename T>
  bool operator()(const T* p_i, const T* yaw_i, const T* p_j, const T* yaw_j, const T* s, T* r) const {
    if (!e(p_i, yaw_i, p_j, yaw_j, r)) return false;
    for (int a = 0; a < 4; ++a) r[a] *= s[0];
    return true;
  }
};

/// Switch prior (1 - s) / sigma (Sünderhauf & Protzel 2012, eq. 4 with Ξ = sigma^2).
struct SwitchPrior {
  double sigma;
  template <typename T>
  bool operator()(const T* s, T* r) const {
    r[0] = (T(1.0) - s[0]) / T(sigma);
    return true;
  }
};

}  // namespace

PoseGraph4Dof::PoseGraph4Dof(const std::vector<RigidPose>& odometry, const PoseGraphOptions& options)
    : options_(options), odometry_(odometry) {
  for (const RigidPose& T : odometry_) {
    pitch_.push_back(pitch_of(T.q));
    roll_.push_back(roll_of(T.q));
  }
  reset_to_odometry();
}

void PoseGraph4Dof::reset_to_odometry() {
  nodes_.resize(odometry_.size());
  for (std::size_t i = 0; i < odometry_.size(); ++i) {
    for (int a = 0; a < 3; ++a) nodes_[i].p[a] = odometry_[i].p[a];
    nodes_[i].yaw[0] = yaw_of(odometry_[i].q);
  }
}

void PoseGraph4Dof::set_estimate(std::size_t i, const RigidPose& T_W_i) {
  for (int a = 0; a < 3; ++a) nodes_[i].p[a] = T_W_i.p[a];
  nodes_[i].yaw[0] = yaw_of(T_W_i.q);
}

RigidPose PoseGraph4Dof::pose(std::size_t i) const {
  return RigidPose{Eigen::Vector3d(nodes_[i].p[0], nodes_[i].p[1], nodes_[i].p[2]),
                   quat_from_ypr(nodes_[i].yaw[0], pitch_[i], roll_[i])};
}

std::vector<RigidPose> PoseGraph4Dof::poses() const {
  std::vector<RigidPose> out;
  out.reserve(nodes_.size());
  for (std::size_t i = 0; i < nodes_.size(); ++i) out.push_back(pose(i));
  return out;
}

namespace {
RelativePoseError loop_error(const LoopEdge& e, const RigidPose& T_W_m_odom, double pitch_m, double roll_m,
                             const PoseGraphOptions& o, double scale) {
  // The loop's relative yaw is taken with the match's odometry roll and pitch, like the position: the
  // edge constrains only what the 4-DoF state can change.
  const double yaw_mk = normalize_angle(yaw_of(T_W_m_odom.q * e.T_m_k.q) - yaw_of(T_W_m_odom.q));
  return RelativePoseError{e.T_m_k.p, yaw_mk, pitch_m, roll_m, o.loop_sigma_t_m, o.loop_sigma_yaw_rad, scale};
}
}  // namespace

double PoseGraph4Dof::loop_residual_sq(const LoopEdge& edge) const {
  const auto m = static_cast<std::size_t>(edge.match), k = static_cast<std::size_t>(edge.query);
  const RelativePoseError f = loop_error(edge, odometry_[m], pitch_[m], roll_[m], options_, 1.0);
  double r[4];
  f(nodes_[m].p, nodes_[m].yaw, nodes_[k].p, nodes_[k].yaw, r);
  return r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3];
}

PoseGraphSolveReport PoseGraph4Dof::solve(const std::vector<LoopEdge>& loops, LoopEdgeLoss loss,
                                          std::vector<double>* switches) {
  PoseGraphSolveReport report;
  if (nodes_.size() < 2) return report;
  ceres::Problem problem;
  ceres::Manifold* angle = new ceres::AutoDiffManifold<AnglePlus, 1, 1>();  // owned by the problem

  for (std::size_t i = 0; i + 1 < nodes_.size(); ++i) {
    // Sequential edge: odometry relative pose in the earlier keyframe's frame (its roll/pitch fixed).
    const RigidPose& a = odometry_[i];
    const RigidPose& b = odometry_[i + 1];
    RelativePoseError f{a.q.conjugate() * (b.p - a.p),
                        normalize_angle(yaw_of(b.q) - yaw_of(a.q)),
                        pitch_[i],
                        roll_[i],
                        options_.seq_sigma_t_m,
                        options_.seq_sigma_yaw_rad,
                        1.0};
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RelativePoseError, 4, 3, 1, 3, 1>(new RelativePoseError(f)), nullptr,
        nodes_[i].p, nodes_[i].yaw, nodes_[i + 1].p, nodes_[i + 1].yaw);
  }

  std::vector<double> local_switches;
  std::vector<double>& s = (switches != nullptr) ? *switches : local_switches;
  if (loss == LoopEdgeLoss::Switchable && s.size() != loops.size()) s.assign(loops.size(), 1.0);

  for (std::size_t l = 0; l < loops.size(); ++l) {
    const LoopEdge& e = loops[l];
    if (e.scale == 0.0 && loss != LoopEdgeLoss::Switchable) continue;
    const auto m = static_cast<std::size_t>(e.match), k = static_cast<std::size_t>(e.query);
    const RelativePoseError f = loop_error(e, odometry_[m], pitch_[m], roll_[m], options_, e.scale);
    if (loss == LoopEdgeLoss::Switchable) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SwitchedPoseError, 4, 3, 1, 3, 1, 1>(new SwitchedPoseError{f}), nullptr,
          nodes_[m].p, nodes_[m].yaw, nodes_[k].p, nodes_[k].yaw, &s[l]);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SwitchPrior, 1, 1>(new SwitchPrior{options_.switch_prior_sigma}), nullptr,
          &s[l]);
      problem.SetParameterLowerBound(&s[l], 0, 0.0);
      problem.SetParameterUpperBound(&s[l], 0, 1.0);
    } else if (loss == LoopEdgeLoss::Huber) {
      // Huber on the whitened residual, times scale^2 outside (ScaledLoss), so the kink stays at delta.
      RelativePoseError unscaled = f;
      unscaled.scale = 1.0;
      auto* lf =
          new ceres::ScaledLoss(new ceres::HuberLoss(options_.huber_delta), e.scale * e.scale, ceres::TAKE_OWNERSHIP);
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RelativePoseError, 4, 3, 1, 3, 1>(new RelativePoseError(unscaled)), lf,
          nodes_[m].p, nodes_[m].yaw, nodes_[k].p, nodes_[k].yaw);
    } else {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<RelativePoseError, 4, 3, 1, 3, 1>(new RelativePoseError(f)), nullptr,
          nodes_[m].p, nodes_[m].yaw, nodes_[k].p, nodes_[k].yaw);
    }
  }

  for (Node& n : nodes_)
    if (problem.HasParameterBlock(n.yaw)) problem.SetManifold(n.yaw, angle);
  // The manifold is shared by all yaw blocks; a problem owns a manifold once (Problem::Options default).
  problem.SetParameterBlockConstant(nodes_[0].p);  // gauge: the first keyframe is fixed
  problem.SetParameterBlockConstant(nodes_[0].yaw);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
                                  ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE)
                              ? ceres::SPARSE_NORMAL_CHOLESKY
                              : ceres::DENSE_QR;
  so.max_num_iterations = options_.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;
  report.iterations = static_cast<int>(summary.iterations.size());
  report.usable = summary.IsSolutionUsable();
  for (Node& n : nodes_) n.yaw[0] = normalize_angle(n.yaw[0]);
  return report;
}

}  // namespace dynavins::loop
