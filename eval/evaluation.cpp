#include "eval/evaluation.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace dynavins::eval {

namespace {

Eigen::Isometry3d to_isometry(const StampedPose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.q.toRotationMatrix();
  T.translation() = p.p;
  return T;
}

}  // namespace

Alignment parse_alignment(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (n == "none") return Alignment::None;
  if (n == "se3") return Alignment::SE3;
  if (n == "sim3") return Alignment::Sim3;
  throw std::invalid_argument("unknown alignment '" + name + "' (expected se3, sim3 or none)");
}

const char* alignment_name(Alignment a) {
  switch (a) {
    case Alignment::None:
      return "none";
    case Alignment::SE3:
      return "se3";
    case Alignment::Sim3:
      return "sim3";
  }
  return "?";
}

Trajectory transformed(const Trajectory& traj, const Similarity3& T) {
  Trajectory out = traj;
  const Eigen::Quaterniond qR(T.R);
  for (StampedPose& p : out.poses) {
    p.p = T(p.p);
    p.q = (qR * p.q).normalized();
  }
  return out;
}

EvalResult evaluate(const Trajectory& gt, const Trajectory& est, const EvalOptions& options) {
  EvalResult r;
  r.gt_poses = gt.size();
  r.est_poses = est.size();
  r.association = associate(gt, est, options.max_dt);
  const std::size_t n = r.association.size();

  Eigen::Matrix3Xd gt_pts(3, static_cast<Eigen::Index>(n));
  Eigen::Matrix3Xd est_pts(3, static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) {
    gt_pts.col(static_cast<Eigen::Index>(k)) = gt.poses[r.association.gt_index[k]].p;
    est_pts.col(static_cast<Eigen::Index>(k)) = est.poses[r.association.est_index[k]].p;
  }
  // Align on the matched positions only, estimate onto ground truth, as evo does.
  if (options.align != Alignment::None) r.alignment = umeyama(est_pts, gt_pts, options.align == Alignment::Sim3);

  std::vector<Eigen::Vector3d> gt_p(n), est_p(n);
  std::vector<Eigen::Isometry3d> gt_T(n), est_T(n);
  const Eigen::Quaterniond qR(r.alignment.R);
  for (std::size_t k = 0; k < n; ++k) {
    const StampedPose& g = gt.poses[r.association.gt_index[k]];
    StampedPose e = est.poses[r.association.est_index[k]];
    e.p = r.alignment(e.p);
    e.q = qR * e.q;
    gt_p[k] = g.p;
    est_p[k] = e.p;
    gt_T[k] = to_isometry(g);
    est_T[k] = to_isometry(e);
  }
  r.ate_errors = ate_translation_errors(gt_p, est_p);
  r.ate = error_stats(r.ate_errors);
  r.rpe_errors = rpe_translation_errors(gt_T, est_T, options.rpe_delta);
  r.rpe = error_stats(r.rpe_errors);
  return r;
}

}  // namespace dynavins::eval
