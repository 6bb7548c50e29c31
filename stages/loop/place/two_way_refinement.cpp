#include "stages/loop/place/two_way_refinement.hpp"

#include <ceres/ceres.h>

namespace dynavins::loop {
namespace {

// r = focal * (π(x) − xy), in pixels.
template <typename T>
void reprojection_px(const Eigen::Matrix<T, 3, 1>& x, const Eigen::Vector2d& xy, double focal, T* r) {
  r[0] = T(focal) * (x.x() / x.z() - T(xy.x()));
  r[1] = T(focal) * (x.y() / x.z() - T(xy.y()));
}

// A match point seen by the query camera: π(q_km p_m + t_km) − xy_k.
struct MatchPointInQuery {
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_km(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_km(t);
    reprojection_px<T>(q_km * p_m.cast<T>() + t_km, xy, focal, r);
    return true;
  }
  Eigen::Vector3d p_m;
  Eigen::Vector2d xy;
  double focal;
};

// A query point seen by the match camera: π(q_km^-1 (p_k − t_km)) − xy_m.
struct QueryPointInMatch {
  template <typename T>
  bool operator()(const T* q, const T* t, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_km(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_km(t);
    reprojection_px<T>(q_km.conjugate() * (p_k.cast<T>() - t_km), xy, focal, r);
    return true;
  }
  Eigen::Vector3d p_k;
  Eigen::Vector2d xy;
  double focal;
};

}  // namespace

bool refine_two_way(const std::vector<TwoWayCorrespondence>& c, Eigen::Quaterniond& q_km, Eigen::Vector3d& t_km,
                    const TwoWayRefinementOptions& o) {
  if (c.size() < 3) return false;
  Eigen::Quaterniond q = q_km.normalized();
  Eigen::Vector3d t = t_km;
  ceres::Problem problem;
  for (const TwoWayCorrespondence& x : c) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<MatchPointInQuery, 2, 4, 3>(
                                 new MatchPointInQuery{x.p_m, x.xy_k, o.focal_px}),
                             new ceres::HuberLoss(o.huber_px), q.coeffs().data(), t.data());
    if (!x.has_p_k) continue;
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<QueryPointInMatch, 2, 4, 3>(
                                 new QueryPointInMatch{x.p_k, x.xy_m, o.focal_px}),
                             new ceres::HuberLoss(o.huber_px), q.coeffs().data(), t.data());
  }
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = o.max_iterations;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable() || !q.coeffs().allFinite() || !t.allFinite()) return false;
  q_km = q.normalized();
  t_km = t;
  return true;
}

}  // namespace dynavins::loop
