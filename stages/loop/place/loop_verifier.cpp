// Descriptor matching, PnP RANSAC in the candidate's camera frame, camera-to-body conversion and the
// plausibility check (see loop_verifier.hpp).
#include "stages/loop/place/loop_verifier.hpp"

#include <cmath>
#include <utility>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "stages/loop/place/two_way_refinement.hpp"

namespace dynavins::loop {

const char* to_string(LoopRejection r) {
  switch (r) {
    case LoopRejection::None:
      return "none";
    case LoopRejection::TooFewMatches:
      return "too few descriptor matches";
    case LoopRejection::PnpFailed:
      return "PnP RANSAC failed";
    case LoopRejection::TooFewInliers:
      return "too few PnP inliers";
    case LoopRejection::Implausible:
      return "implausible relative pose";
  }
  return "?";
}

namespace {
/// A keyframe's camera in its (odometry) world frame: T_wc = T_wb * T_bc.
std::pair<Eigen::Quaterniond, Eigen::Vector3d> camera_in_world(const KeyframeDescriptors& kf) {
  return {(kf.q_wb * kf.q_bc).normalized(), kf.p_wb + kf.q_wb * kf.p_bc};
}
}  // namespace

LoopVerification LoopVerifier::verify(const KeyframeDescriptors& query, const KeyframeDescriptors& match) const {
  LoopVerification v;
  v.loop.query_t_ns = query.t_ns;
  v.loop.match_t_ns = match.t_ns;
  const std::vector<DescriptorMatch> matches = match_descriptors(query, match, opts_.matching);
  v.matches = static_cast<int>(matches.size());
  if (v.matches < std::max(opts_.min_inliers, 4)) {
    v.rejection = LoopRejection::TooFewMatches;
    return v;
  }

  // The candidate's camera C_m in its (odometry) world frame.
  const auto [q_wc, p_wc] = camera_in_world(match);
  const Eigen::Matrix3d R_cw = q_wc.conjugate().toRotationMatrix();
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  object.reserve(matches.size());
  image.reserve(matches.size());
  for (const DescriptorMatch& m : matches) {
    const Eigen::Vector3d p_c = R_cw * (match.points[m.match].p_w - p_wc);
    object.emplace_back(p_c.x(), p_c.y(), p_c.z());
    const Eigen::Vector2d& xy = query.points[m.query].xy;
    image.emplace_back(xy.x(), xy.y());
  }

  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  bool ok = false;
  try {
    ok = cv::solvePnPRansac(object, image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, false,
                            opts_.ransac_iterations, static_cast<float>(opts_.reprojection_px / opts_.focal_px),
                            opts_.ransac_confidence, inliers, cv::SOLVEPNP_ITERATIVE);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok || rvec.empty() || tvec.empty()) {
    v.rejection = LoopRejection::PnpFailed;
    return v;
  }
  v.inliers = static_cast<int>(inliers.size());

  // PnP gives T_ck_cm (candidate camera points into the query camera); invert, then to bodies:
  // T_bm_bk = T_bc(m) * T_cm_ck * T_bc(k)^-1.
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R_kc_mc;
  Eigen::Vector3d t_kc_mc;
  cv::cv2eigen(R_cv, R_kc_mc);
  cv::cv2eigen(tvec, t_kc_mc);
  if (opts_.two_way_refinement && static_cast<int>(inliers.size()) >= opts_.min_inliers) {
    // The query camera C_k in its own odometry world frame, for its points.
    const auto [q_wck, p_wck] = camera_in_world(query);
    std::vector<TwoWayCorrespondence> c;
    c.reserve(inliers.size());
    for (const int i : inliers) {
      const DescriptorMatch& m = matches[static_cast<std::size_t>(i)];
      TwoWayCorrespondence x;
      x.p_m = Eigen::Vector3d(object[i].x, object[i].y, object[i].z);
      x.xy_k = query.points[m.query].xy;
      x.xy_m = match.points[m.match].xy;
      x.has_p_k = query.points[m.query].has_p_w && x.xy_m.allFinite();
      if (x.has_p_k) x.p_k = q_wck.conjugate() * (query.points[m.query].p_w - p_wck);
      c.push_back(x);
    }
    Eigen::Quaterniond q_km(R_kc_mc);
    TwoWayRefinementOptions ro;
    ro.focal_px = opts_.focal_px;
    if (refine_two_way(c, q_km, t_kc_mc, ro)) R_kc_mc = q_km.toRotationMatrix();
  }
  const Eigen::Quaterniond q_mc_kc(R_kc_mc.transpose());
  const Eigen::Vector3d p_mc_kc = -(R_kc_mc.transpose() * t_kc_mc);
  const Eigen::Quaterniond q_kc_kb = query.q_bc.conjugate();
  const Eigen::Vector3d p_kc_kb = -(q_kc_kb * query.p_bc);
  const Eigen::Quaterniond q_mc_kb = q_mc_kc * q_kc_kb;
  const Eigen::Vector3d p_mc_kb = p_mc_kc + q_mc_kc * p_kc_kb;
  v.loop.q_mq = (match.q_bc * q_mc_kb).normalized();
  v.loop.p_mq = match.p_bc + match.q_bc * p_mc_kb;
  v.loop.inliers = v.inliers;

  if (v.inliers < opts_.min_inliers) {
    v.rejection = LoopRejection::TooFewInliers;
    return v;
  }
  const double angle_deg = Eigen::AngleAxisd(v.loop.q_mq).angle() * 180.0 / M_PI;
  if (!v.loop.p_mq.allFinite() || v.loop.p_mq.norm() > opts_.max_translation_m ||
      !(angle_deg <= opts_.max_rotation_deg)) {
    v.rejection = LoopRejection::Implausible;
    return v;
  }
  v.accepted = true;
  return v;
}

}  // namespace dynavins::loop
