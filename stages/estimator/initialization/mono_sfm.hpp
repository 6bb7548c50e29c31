#pragma once
// Vision-only structure from motion over the initialisation window (VINS-Mono T-RO 2018 §V-A; VINS-Mono
// code: relative_pose + GlobalSFM::construct):
//  1. reference frame l = the earliest frame with enough features in common with the newest frame and
//     enough parallax (raw, and not explainable by a pure rotation) among the features that moved;
//  2. l <-> newest from the essential matrix (5-point RANSAC + cheirality), unit baseline;
//  3. triangulate, then PnP the frames outward from l and the newest one, triangulating as they come;
//  4. bundle adjustment of all camera poses and points (frame l fixed, newest distance to l = 1: scale),
//     points with a reprojection error above a threshold dropped and the BA solved again.
// Output is up to scale, in frame l's camera coordinates.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/estimator/initialization/frame_features.hpp"

namespace dynavins::estimator {

/// Settings of solve_mono_sfm(). Pixel quantities are converted with focal_px to the normalized plane.
struct MonoSfmOptions {
  double focal_px = 460.0;                ///< focal length used to express thresholds in pixels (VINS: 460)
  int min_common_features = 20;           ///< features shared by l and the newest frame (VINS: > 20)
  double min_parallax_px = 30.0;          ///< mean raw feature displacement l <-> newest (VINS: 30 px)
  /// Features that move with the camera (a truck leading it a few metres ahead, issue 23) keep their
  /// pixels while it drives: averaged in as VINS does, they dilute the mean parallax (behind a truck that
  /// covers half the view a camera driving at 3 m/s never reached 30 px), they satisfy any essential
  /// matrix with R ~ I, and triangulated they enter the SfM's BA as outliers. Points at infinity on a
  /// straight drive keep their pixels too, and in two views nothing tells them apart; but far points are
  /// real structure whose low parallax VINS' mean rightly counts. So: a feature is "still" when it moved
  /// less than min_feature_motion_px between l and the newest frame (one sigma of the reprojection noise
  /// VINS-Fusion configs declare: less is not measurable parallax). While at most max_still_share of the
  /// common features are still, everything is as in VINS (mean over all, all features in the essential
  /// matrix and triangulated). Above it the still ones are taken for riders: the parallax tests and the
  /// essential matrix use the moved features only and the still ones are never triangulated.
  /// Why a third: below it VINS' mean still reaches 30 px once the moving features' own mean reaches
  /// 45 px, which an 11-frame window gives at driving speeds; static scenes measured 6-9 % still at
  /// initialisation, the truck-led drive 57 %.
  double max_still_share = 1.0 / 3.0;
  double min_feature_motion_px = 1.5;
  /// Median displacement left after the best pure-rotation fit of l <-> newest: below it the pair is
  /// (close to) a pure rotation and the translation / structure are not observable. Not in VINS.
  double min_translation_parallax_px = 5.0;
  double ransac_threshold_px = 1.0;       ///< essential-matrix RANSAC threshold (VINS: 0.3 px, noise-tight)
  int min_essential_inliers = 12;         ///< inliers after cheirality (VINS: 12)
  int min_pnp_points = 10;                ///< triangulated features needed to PnP a frame (VINS: 10)
  double cauchy_px = 2.0;                 ///< Cauchy loss scale of the BA residuals [px] (bad tracks)
  /// PnP RANSAC threshold, and BA outlier test: a point with any reprojection error above it is dropped.
  double outlier_threshold_px = 4.0;
  double min_inlier_point_fraction = 0.5; ///< fail when BA keeps fewer of the triangulated points
  double max_rms_reprojection_px = 3.0;   ///< BA result rejected above this RMS reprojection error
  int max_ba_iterations = 100;            ///< Ceres iterations of the final BA
};

/// Result of solve_mono_sfm(). Poses and points are in frame l's camera coordinates, up to one scale.
struct MonoSfmResult {
  bool success = false;
  std::string reason;                   ///< why it failed (empty on success)
  int reference_frame = -1;             ///< l
  std::vector<Eigen::Matrix3d> R_lc;    ///< camera-to-l rotation of every frame
  std::vector<Eigen::Vector3d> p_lc;    ///< camera position of every frame in l
  std::map<FeatureId, Eigen::Vector3d> points_l;  ///< triangulated features (id -> position in l)
  double rms_reprojection_px = 0.0;     ///< after BA
};

/// Runs the vision-only SfM on the frames' observations (index 0 = oldest, back() = newest).
/// Never throws on bad data: returns success == false with a reason.
MonoSfmResult solve_mono_sfm(const std::vector<FrameFeatures>& frames, const MonoSfmOptions& options = {});

/// Median pixel displacement between matched bearings left after the least-squares pure rotation
/// (Kabsch) that maps the first frame's bearings onto the second's. ~0 for a pure rotation.
double rotation_compensated_parallax_px(const std::vector<Eigen::Vector2d>& x_a, const std::vector<Eigen::Vector2d>& x_b,
                                     double focal_px);

/// Two-view linear (DLT) triangulation of a point in the world from world-to-camera poses
/// (R_cw, t_cw) and normalized observations. Returns false when the point is not in front of both.
bool triangulate_two_views(const Eigen::Matrix3d& R_cw_a, const Eigen::Vector3d& t_cw_a, const Eigen::Vector2d& x_a,
                         const Eigen::Matrix3d& R_cw_b, const Eigen::Vector3d& t_cw_b, const Eigen::Vector2d& x_b,
                         Eigen::Vector3d& p_w);

}  // namespace dynavins::estimator
