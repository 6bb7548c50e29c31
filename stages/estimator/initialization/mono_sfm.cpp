#include "stages/estimator/initialization/mono_sfm.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include <ceres/ceres.h>
#include <ceres/sphere_manifold.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace dynavins::estimator {
namespace {

// World-to-camera pose (the form PnP and projection use); world = frame l's camera.
struct CameraPose {
  Eigen::Quaterniond q_cw = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t_cw = Eigen::Vector3d::Zero();
};

// Reprojection error on the normalized plane, scaled to pixels so the loss scale reads in pixels.
struct ReprojectionError {
  ReprojectionError(const Eigen::Vector2d& obs, double focal) : obs(obs), focal(focal) {}
  template <typename T>
  bool operator()(const T* q, const T* t, const T* p, T* r) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_cw(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_cw(t), p_w(p);
    const Eigen::Matrix<T, 3, 1> p_c = q_cw * p_w + t_cw;
    r[0] = T(focal) * (p_c.x() / p_c.z() - T(obs.x()));
    r[1] = T(focal) * (p_c.y() / p_c.z() - T(obs.y()));
    return true;
  }
  Eigen::Vector2d obs;
  double focal;
};

Eigen::Vector3d bearing(const Eigen::Vector2d& x) { return Eigen::Vector3d(x.x(), x.y(), 1.0).normalized(); }

// Matched observations of two frames.
struct Correspondences {
  std::vector<FeatureId> ids;
  std::vector<Eigen::Vector2d> a, b;
};

Correspondences correspondences(const FrameFeatures& fa, const FrameFeatures& fb) {
  Correspondences c;
  for (const auto& [id, xa] : fa) {
    const auto it = fb.find(id);
    if (it == fb.end()) continue;
    c.ids.push_back(id);
    c.a.push_back(xa);
    c.b.push_back(it->second);
  }
  return c;
}

// Whether correspondence i moved less than min_motion_px in the image (MonoSfmOptions::min_feature_motion_px).
bool still_in_image(const Correspondences& c, size_t i, double min_motion_px, double focal) {
  return focal * (c.a[i] - c.b[i]).norm() < min_motion_px;
}

// The correspondences that are not still_in_image.
Correspondences moved_in_image(const Correspondences& c, double min_motion_px, double focal) {
  Correspondences m;
  for (size_t i = 0; i < c.a.size(); ++i) {
    if (still_in_image(c, i, min_motion_px, focal)) continue;
    m.ids.push_back(c.ids[i]);
    m.a.push_back(c.a[i]);
    m.b.push_back(c.b[i]);
  }
  return m;
}

double mean_parallax_px(const Correspondences& c, double focal) {
  double sum = 0.0;
  for (size_t i = 0; i < c.a.size(); ++i) sum += (c.a[i] - c.b[i]).norm();
  return c.a.empty() ? 0.0 : focal * sum / static_cast<double>(c.a.size());
}

// Relative pose from the essential matrix: x_b = R x_a + t (|t| = 1). False when too few inliers survive.
bool relative_pose_from_essential(const Correspondences& c, const MonoSfmOptions& o, Eigen::Matrix3d& R,
                               Eigen::Vector3d& t) {
  if (c.a.size() < 8) return false;
  std::vector<cv::Point2d> pa, pb;
  for (size_t i = 0; i < c.a.size(); ++i) {
    pa.emplace_back(c.a[i].x(), c.a[i].y());
    pb.emplace_back(c.b[i].x(), c.b[i].y());
  }
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);  // points are already normalized
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(pa, pb, K, cv::RANSAC, 0.999, o.ransac_threshold_px / o.focal_px, mask);
  if (E.rows != 3 || E.cols != 3) return false;  // degenerate: several or no solutions
  cv::Mat cvR, cvt;
  const int inliers = cv::recoverPose(E, pa, pb, K, cvR, cvt, mask);
  if (inliers < o.min_essential_inliers) return false;
  cv::cv2eigen(cvR, R);
  cv::cv2eigen(cvt, t);
  return true;
}

Eigen::Vector2d project(const CameraPose& pose, const Eigen::Vector3d& p_w, double* depth = nullptr) {
  const Eigen::Vector3d p_c = pose.q_cw * p_w + pose.t_cw;
  if (depth) *depth = p_c.z();
  return p_c.head<2>() / p_c.z();
}

class SfmBuilder {
 public:
  SfmBuilder(const std::vector<FrameFeatures>& frames, const MonoSfmOptions& o)
      : frames_(frames), o_(o), poses_(frames.size()) {}

  MonoSfmResult run();

 private:
  bool choose_reference_frame(int& l, Eigen::Matrix3d& R, Eigen::Vector3d& t, bool& riders, std::string& why) const;
  void triangulate_pair(int a, int b);
  bool solve_pn_p(int k, int guess_from, std::string& why);
  void triangulate_remaining();
  bool bundle_adjust(std::string& why);
  bool solve_bundle_adjustment(std::string& why);
  int remove_outlier_points();

  const std::vector<FrameFeatures>& frames_;
  const MonoSfmOptions& o_;
  std::vector<CameraPose> poses_;
  std::map<FeatureId, Eigen::Vector3d> points_;
  /// When riders were suspected at l (MonoSfmOptions::max_still_share): the features common to l and the
  /// newest frame that moved less than min_feature_motion_px between them, never triangulated (they would
  /// enter the BA as outliers). Empty otherwise.
  std::set<FeatureId> still_;
  double rms_px_ = 0.0;
  int reference_ = 0;
};

bool SfmBuilder::choose_reference_frame(int& l, Eigen::Matrix3d& R, Eigen::Vector3d& t, bool& riders,
                                        std::string& why) const {
  const int newest = static_cast<int>(frames_.size()) - 1;
  int best_common = 0, best_moved = 0;
  double best_parallax = 0.0, best_translation_parallax = 0.0;
  for (int i = 0; i < newest; ++i) {
    const Correspondences all = correspondences(frames_[i], frames_[newest]);
    const int n = static_cast<int>(all.ids.size());
    best_common = std::max(best_common, n);
    if (n < o_.min_common_features) continue;
    // Too many still features to be far points alone: parallax, pure-rotation test and essential matrix
    // on the features that moved (MonoSfmOptions::max_still_share).
    const Correspondences moved_only = moved_in_image(all, o_.min_feature_motion_px, o_.focal_px);
    const int moved = static_cast<int>(moved_only.ids.size());
    const bool riders_here = n - moved > o_.max_still_share * n;
    const Correspondences& c = riders_here ? moved_only : all;
    best_moved = std::max(best_moved, static_cast<int>(c.ids.size()));
    if (riders_here && moved < o_.min_common_features) continue;
    const double parallax = mean_parallax_px(c, o_.focal_px);
    best_parallax = std::max(best_parallax, parallax);
    if (parallax < o_.min_parallax_px) continue;
    const double translation_parallax = rotation_compensated_parallax_px(c.a, c.b, o_.focal_px);
    best_translation_parallax = std::max(best_translation_parallax, translation_parallax);
    if (translation_parallax < o_.min_translation_parallax_px) continue;
    if (!relative_pose_from_essential(c, o_, R, t)) continue;
    l = i;
    riders = riders_here;
    return true;
  }
  // Name the first test that no candidate frame passed (the tests run in this order).
  const auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    return std::string(buf);
  };
  if (best_common < o_.min_common_features) {
    why = "no reference frame: at most " + std::to_string(best_common) + " common features with the newest frame (need " +
          std::to_string(o_.min_common_features) + ")";
  } else if (best_moved < o_.min_common_features) {
    why = "not enough parallax: at most " + std::to_string(best_moved) + " common features moved " +
          num(o_.min_feature_motion_px) + " px or more (need " + std::to_string(o_.min_common_features) +
          "); the camera has not moved enough, or what it sees moves with it";
  } else if (best_parallax < o_.min_parallax_px) {
    why = "not enough parallax: at most " + num(best_parallax) + " px mean feature motion (need " +
          num(o_.min_parallax_px) + "); the camera has not moved enough";
  } else if (best_translation_parallax < o_.min_translation_parallax_px) {
    why = "motion close to a pure rotation: at most " + num(best_translation_parallax) +
          " px parallax beyond the best pure rotation (need " + num(o_.min_translation_parallax_px) + ")";
  } else {
    why = "no reference frame: the essential matrix failed for every frame with enough parallax";
  }
  return false;
}

void SfmBuilder::triangulate_pair(int a, int b) {
  const Correspondences c = correspondences(frames_[a], frames_[b]);
  const CameraPose &A = poses_[a], &B = poses_[b];
  for (size_t i = 0; i < c.ids.size(); ++i) {
    if (points_.count(c.ids[i]) || still_.count(c.ids[i])) continue;
    Eigen::Vector3d p;
    if (triangulate_two_views(A.q_cw.toRotationMatrix(), A.t_cw, c.a[i], B.q_cw.toRotationMatrix(), B.t_cw, c.b[i], p))
      points_[c.ids[i]] = p;
  }
}

bool SfmBuilder::solve_pn_p(int k, int guess_from, std::string& why) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (const auto& [id, x] : frames_[k]) {
    const auto it = points_.find(id);
    if (it == points_.end()) continue;
    object.emplace_back(it->second.x(), it->second.y(), it->second.z());
    image.emplace_back(x.x(), x.y());
  }
  if (static_cast<int>(object.size()) < o_.min_pnp_points) {
    why = "PnP of frame " + std::to_string(k) + ": only " + std::to_string(object.size()) +
          " triangulated features (need " + std::to_string(o_.min_pnp_points) + ")";
    return false;
  }
  // Neighbouring frame's pose as the initial guess (frames are close in time).
  const Eigen::Matrix3d R_guess = poses_[guess_from].q_cw.toRotationMatrix();
  cv::Mat cvR, rvec, tvec;
  cv::eigen2cv(R_guess, cvR);
  cv::Rodrigues(cvR, rvec);
  cv::eigen2cv(Eigen::Vector3d(poses_[guess_from].t_cw), tvec);
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  // RANSAC: badly triangulated points and bad tracks must not pull the pose; inliers refined iteratively.
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object, image, K, cv::Mat(), rvec, tvec, true, 100,
                          static_cast<float>(o_.outlier_threshold_px / o_.focal_px), 0.99, inliers,
                          cv::SOLVEPNP_ITERATIVE) ||
      static_cast<int>(inliers.size()) < o_.min_pnp_points) {
    why = "PnP of frame " + std::to_string(k) + " failed (" + std::to_string(inliers.size()) + " inliers of " +
          std::to_string(object.size()) + ")";
    return false;
  }
  cv::Rodrigues(rvec, cvR);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(cvR, R);
  cv::cv2eigen(tvec, t);
  if (!R.allFinite() || !t.allFinite()) {
    why = "PnP of frame " + std::to_string(k) + " gave a non-finite pose";
    return false;
  }
  poses_[k].q_cw = Eigen::Quaterniond(R);
  poses_[k].t_cw = t;
  return true;
}

void SfmBuilder::triangulate_remaining() {
  // Features not yet triangulated: use the first and last frames that observe them.
  std::map<FeatureId, std::pair<int, int>> span;
  for (int k = 0; k < static_cast<int>(frames_.size()); ++k)
    for (const auto& observation : frames_[k]) {
      const auto it = span.find(observation.first);
      if (it == span.end()) span[observation.first] = {k, k};
      else it->second.second = k;
    }
  for (const auto& [id, fl] : span) {
    if (points_.count(id) || still_.count(id) || fl.first == fl.second) continue;
    const CameraPose &A = poses_[fl.first], &B = poses_[fl.second];
    Eigen::Vector3d p;
    if (triangulate_two_views(A.q_cw.toRotationMatrix(), A.t_cw, frames_[fl.first].at(id), B.q_cw.toRotationMatrix(),
                            B.t_cw, frames_[fl.second].at(id), p))
      points_[id] = p;
  }
}

bool SfmBuilder::solve_bundle_adjustment(std::string& why) {
  const int n = static_cast<int>(frames_.size());
  std::vector<std::array<double, 4>> q(n);
  std::vector<std::array<double, 3>> t(n);
  for (int k = 0; k < n; ++k) {
    Eigen::Map<Eigen::Quaterniond>(q[k].data()) = poses_[k].q_cw;
    Eigen::Map<Eigen::Vector3d>(t[k].data()) = poses_[k].t_cw;
  }
  std::map<FeatureId, std::array<double, 3>> pts;
  for (const auto& [id, p] : points_) pts[id] = {p.x(), p.y(), p.z()};

  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::SphereManifold<3> unit_sphere;
  for (int k = 0; k < n; ++k) {
    problem.AddParameterBlock(q[k].data(), 4, &quaternion_manifold);
    // |t_cw| of the newest frame = its distance to frame l: kept at 1 to fix the scale (below).
    problem.AddParameterBlock(t[k].data(), 3, k == n - 1 ? &unit_sphere : nullptr);
    for (const auto& [id, x] : frames_[k]) {
      const auto it = pts.find(id);
      if (it == pts.end()) continue;
      auto* cost =
          new ceres::AutoDiffCostFunction<ReprojectionError, 2, 4, 3, 3>(new ReprojectionError(x, o_.focal_px));
      problem.AddResidualBlock(cost, new ceres::CauchyLoss(o_.cauchy_px), q[k].data(), t[k].data(), it->second.data());
    }
  }
  // Gauge (7 DoF): frame l fixed, the newest frame's distance to l fixed to 1 (scale). VINS's GlobalSFM
  // fixes the newest translation entirely, which also freezes its direction at the two-view estimate.
  problem.SetParameterBlockConstant(q[reference_].data());
  problem.SetParameterBlockConstant(t[reference_].data());

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_SCHUR;
  so.max_num_iterations = o_.max_ba_iterations;
  so.num_threads = 1;
  // The cost is dominated by the noise floor; the default relative tolerance (1e-6) may stop while the
  // poses still drift along weakly constrained directions.
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    why = "SfM bundle adjustment failed: " + summary.message;
    return false;
  }
  for (int k = 0; k < n; ++k) {
    poses_[k].q_cw = Eigen::Map<const Eigen::Quaterniond>(q[k].data()).normalized();
    poses_[k].t_cw = Eigen::Map<const Eigen::Vector3d>(t[k].data());
  }
  for (auto& [id, p] : points_) p = Eigen::Vector3d(pts[id][0], pts[id][1], pts[id][2]);
  return true;
}

int SfmBuilder::remove_outlier_points() {
  // A point behind a camera that sees it, or with any reprojection error above the threshold, is a bad
  // track (or badly triangulated): dropped whole. rms_px_ is measured on the points kept.
  double sq = 0.0;
  int count = 0, removed = 0;
  for (auto it = points_.begin(); it != points_.end();) {
    bool good = true;
    double sq_point = 0.0;
    int count_point = 0;
    for (size_t k = 0; k < frames_.size(); ++k) {
      const auto obs = frames_[k].find(it->first);
      if (obs == frames_[k].end()) continue;
      double depth = 0.0;
      const Eigen::Vector2d x = project(poses_[k], it->second, &depth);
      const double e2 = (o_.focal_px * (x - obs->second)).squaredNorm();
      if (!(depth > 0.0) || !(e2 <= o_.outlier_threshold_px * o_.outlier_threshold_px)) good = false;
      sq_point += e2;
      ++count_point;
    }
    if (!good) {
      it = points_.erase(it);
      ++removed;
      continue;
    }
    sq += sq_point;
    count += count_point;
    ++it;
  }
  rms_px_ = count > 0 ? std::sqrt(sq / count) : 0.0;
  return removed;
}

bool SfmBuilder::bundle_adjust(std::string& why) {
  const size_t triangulated = points_.size();
  if (!solve_bundle_adjustment(why)) return false;
  // Outliers still pull the first solution a little (the Cauchy loss bounds it); solve again without them.
  if (remove_outlier_points() > 0) {
    if (!solve_bundle_adjustment(why)) return false;
    remove_outlier_points();
  }
  if (static_cast<double>(points_.size()) < o_.min_inlier_point_fraction * static_cast<double>(triangulated)) {
    why = "SfM bundle adjustment kept only " + std::to_string(points_.size()) + " of " +
          std::to_string(triangulated) + " points";
    return false;
  }
  if (points_.empty() || rms_px_ > o_.max_rms_reprojection_px) {
    why = "SfM bundle adjustment RMS reprojection error " + std::to_string(rms_px_) + " px above " +
          std::to_string(o_.max_rms_reprojection_px) + " px";
    return false;
  }
  return true;
}

MonoSfmResult SfmBuilder::run() {
  MonoSfmResult res;
  const int n = static_cast<int>(frames_.size());
  if (n < 3) {
    res.reason = "SfM needs at least 3 frames, got " + std::to_string(n);
    return res;
  }
  const int newest = n - 1;
  int l = -1;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  bool riders = false;
  if (!choose_reference_frame(l, R, t, riders, res.reason)) return res;
  reference_ = l;
  const Correspondences common = correspondences(frames_[l], frames_[newest]);
  for (size_t i = 0; riders && i < common.ids.size(); ++i)
    if (still_in_image(common, i, o_.min_feature_motion_px, o_.focal_px)) still_.insert(common.ids[i]);
  poses_[newest].q_cw = Eigen::Quaterniond(R);  // x_newest = R x_l + t is the world(l)-to-camera map
  poses_[newest].t_cw = t;

  // Frames l+1 .. newest-1 by PnP, triangulating each against the newest frame; then against l.
  for (int i = l; i < newest; ++i) {
    if (i > l && !solve_pn_p(i, i - 1, res.reason)) return res;
    triangulate_pair(i, newest);
  }
  for (int i = l + 1; i < newest; ++i) triangulate_pair(l, i);
  // Frames older than l, outward, triangulated against l.
  for (int i = l - 1; i >= 0; --i) {
    if (!solve_pn_p(i, i + 1, res.reason)) return res;
    triangulate_pair(i, l);
  }
  triangulate_remaining();
  if (!bundle_adjust(res.reason)) return res;

  res.success = true;
  res.reference_frame = l;
  res.rms_reprojection_px = rms_px_;
  res.points_l = points_;
  for (int k = 0; k < n; ++k) {
    const Eigen::Matrix3d R_lc = poses_[k].q_cw.toRotationMatrix().transpose();
    res.R_lc.push_back(R_lc);
    res.p_lc.push_back(-R_lc * poses_[k].t_cw);
  }
  return res;
}

}  // namespace

double rotation_compensated_parallax_px(const std::vector<Eigen::Vector2d>& x_a, const std::vector<Eigen::Vector2d>& x_b,
                                     double focal_px) {
  if (x_a.empty() || x_a.size() != x_b.size()) return 0.0;
  // Kabsch: R = argmax Σ f_b^T R f_a from the SVD of Σ f_b f_a^T.
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < x_a.size(); ++i) M += bearing(x_b[i]) * bearing(x_a[i]).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  std::vector<double> residual;
  residual.reserve(x_a.size());
  for (size_t i = 0; i < x_a.size(); ++i) {
    const Eigen::Vector3d f = R * Eigen::Vector3d(x_a[i].x(), x_a[i].y(), 1.0);
    if (f.z() <= 1e-9) {
      residual.push_back(1e9);  // rotated behind the camera: certainly not a pure rotation
      continue;
    }
    residual.push_back(focal_px * (f.head<2>() / f.z() - x_b[i]).norm());
  }
  auto mid = residual.begin() + residual.size() / 2;
  std::nth_element(residual.begin(), mid, residual.end());
  return *mid;
}

bool triangulate_two_views(const Eigen::Matrix3d& R_cw_a, const Eigen::Vector3d& t_cw_a, const Eigen::Vector2d& x_a,
                         const Eigen::Matrix3d& R_cw_b, const Eigen::Vector3d& t_cw_b, const Eigen::Vector2d& x_b,
                         Eigen::Vector3d& p_w) {
  // x × (P X) = 0 for each view gives two rows per view (Hartley & Zisserman §12.2).
  Eigen::Matrix<double, 3, 4> Pa, Pb;
  Pa << R_cw_a, t_cw_a;
  Pb << R_cw_b, t_cw_b;
  Eigen::Matrix4d A;
  A.row(0) = x_a.x() * Pa.row(2) - Pa.row(0);
  A.row(1) = x_a.y() * Pa.row(2) - Pa.row(1);
  A.row(2) = x_b.x() * Pb.row(2) - Pb.row(0);
  A.row(3) = x_b.y() * Pb.row(2) - Pb.row(1);
  const Eigen::Vector4d X = Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return false;  // at infinity
  p_w = X.head<3>() / X.w();
  return (R_cw_a * p_w + t_cw_a).z() > 0.0 && (R_cw_b * p_w + t_cw_b).z() > 0.0 && p_w.allFinite();
}

MonoSfmResult solve_mono_sfm(const std::vector<FrameFeatures>& frames, const MonoSfmOptions& options) {
  return SfmBuilder(frames, options).run();
}

}  // namespace dynavins::estimator
