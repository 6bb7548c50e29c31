#include "stages/estimator/initialization/mono_initializer.hpp"

#include <Eigen/Geometry>

#include "stages/estimator/initialization/gravity_alignment.hpp"
#include "stages/estimator/initialization/gyro_bias_estimator.hpp"

namespace dynavins::estimator {

MonoInitResult initialize_mono(const std::vector<InitWindowFrame>& window, const Eigen::Matrix3d& R_bc,
                              const Eigen::Vector3d& p_bc, const MonoInitOptions& o) {
  MonoInitResult res;
  const int n = static_cast<int>(window.size());
  if (n < 3) {
    res.reason = "initialisation needs at least 3 frames, got " + std::to_string(n);
    return res;
  }
  std::vector<const imu::ImuPreintegration*> preints;
  for (int k = 1; k < n; ++k) {
    if (window[k].preint == nullptr) {
      res.reason = "frame " + std::to_string(k) + " has no preintegration";
      return res;
    }
    preints.push_back(window[k].preint);
  }

  // §V-A: vision-only SfM, frame c0 = SfM reference frame l.
  std::vector<FrameFeatures> features;
  for (const InitWindowFrame& f : window) features.push_back(f.features);
  const MonoSfmResult sfm = solve_mono_sfm(features, o.sfm);
  if (!sfm.success) {
    res.reason = sfm.reason;
    return res;
  }
  res.sfm_succeeded = true;
  res.sfm_reference_frame = sfm.reference_frame;
  res.sfm_rms_reprojection_px = sfm.rms_reprojection_px;
  std::vector<Eigen::Matrix3d> R_c0_b(n);
  for (int k = 0; k < n; ++k) R_c0_b[k] = sfm.R_lc[k] * R_bc.transpose();

  // §V-B-1: gyroscope bias, then repropagation at the new bias (all intervals share it).
  res.bg = preints.front()->linearized_bg() + estimate_gyro_bias(R_c0_b, preints);
  for (int k = 1; k < n; ++k) window[k].preint->repropagate(window[k].preint->linearized_ba(), res.bg);

  // §V-B-2/3: velocities, gravity, scale.
  const VisualInertialAlignment al = align_visual_inertial(R_c0_b, sfm.p_lc, preints, p_bc, o.alignment);
  if (!al.success) {
    res.reason = al.reason;
    return res;
  }
  res.scale = al.scale;
  res.scale_relative_std = al.scale_relative_std;

  // World: gravity on -z, then the yaw of frame 0's body removed (a rotation about z keeps gravity).
  Eigen::Matrix3d R_wc0 = rotation_aligning_gravity(al.g_c0);
  R_wc0 = Eigen::AngleAxisd(-yaw_of(R_wc0 * R_c0_b[0]), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_wc0;
  // Metric body positions in c0: p_b = s p̄_c - R_c0_b p_bc; origin moved to frame 0's body.
  std::vector<Eigen::Vector3d> p_c0_b(n);
  for (int k = 0; k < n; ++k) p_c0_b[k] = al.scale * sfm.p_lc[k] - R_c0_b[k] * p_bc;
  for (int k = 0; k < n; ++k) {
    res.R_wb.push_back(R_wc0 * R_c0_b[k]);
    res.p_wb.push_back(R_wc0 * (p_c0_b[k] - p_c0_b[0]));
    res.v_wb.push_back(res.R_wb.back() * al.v_b[k]);
  }

  // Feature depths in their anchor camera: the SfM point and camera scaled by s.
  for (const auto& [id, P] : sfm.points_l) {
    for (int k = 0; k < n; ++k) {
      if (!window[k].features.count(id)) continue;
      const double depth = al.scale * (sfm.R_lc[k].transpose() * (P - sfm.p_lc[k])).z();
      if (depth > 0.0) res.depths[id] = FeatureDepth{k, depth};
      break;
    }
  }
  res.success = true;
  return res;
}

}  // namespace dynavins::estimator
