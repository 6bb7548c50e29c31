#pragma once
// Options of the stereo KLT tracker; VINS-Fusion's defaults (its feature_tracker.cpp) where it has one.

#include "stages/common/estimator_options.hpp"

namespace dynavins::tracker {

struct TrackerOptions {
  int max_cnt = 150;      ///< features kept per frame
  double min_dist = 30;   ///< [px] minimum distance between features (mask radius)
  bool flow_back = true;  ///< forward-backward check on the temporal KLT
  /// [px] a track survives the backward check when it returns within this of where it started;
  /// also the left-right-left bound of the stereo check (VINS-Fusion: 0.5).
  double max_back_error = 0.5;
  bool f_ransac = false;     ///< fundamental-matrix RANSAC on temporal tracks (VINS-Fusion: off)
  double f_threshold = 1.0;  ///< [px] RANSAC threshold on a virtual 460 px focal length
  bool clahe = false;        ///< contrast-limited equalization before tracking (dark scenes; key equalize)
  double clahe_clip = 3.0;
  bool stereo_gain_match = true;  ///< scale the right image to the left's mean before stereo KLT
  /// A track without a right match searches again only every this many frames (1: every frame). On
  /// the EuRoC clip 4 keeps the stereo match rate (0.51 either way) and runs a failing search a quarter as often.
  int stereo_retry_interval = 4;
  /// Align each track's first patch (affine warp, gain / offset) after the KLT and move the track onto
  /// it: frame-to-frame KLT drifts, the first patch does not (patch_template.hpp).
  bool patch_refine = true;
  /// [px] a refinement landing farther than this from the KLT answer means the two disagree on what
  /// the feature is: the track ends. Generous: on a healthy track the two differ by ~0.3 px.
  double patch_max_shift = 2.0;
  /// The patch is captured again at the refined pixel when its apparent size has changed by more than
  /// this factor (the affine model of a plane patch is only local).
  double patch_recapture_scale = 1.5;
  int pyramid_levels = 3;  ///< maxLevel of the pyramids (levels above the full image)
  int window = 21;         ///< [px] KLT window side
  int max_iterations = 30;
  double epsilon = 0.01;
  double quality_level = 0.01;  ///< corner threshold, relative to the strongest unmasked corner
  int border = 1;               ///< [px] features this close to the edge are dropped

  /// The tracker keys of a loaded VINS-Fusion / DynaVINS / VINS-Mono config (the rest keep the defaults).
  static TrackerOptions from(const EstimatorOptions& o) {
    TrackerOptions t;
    t.max_cnt = o.max_cnt;
    t.min_dist = o.min_dist;
    t.flow_back = o.flow_back;
    t.patch_refine = o.patch_refine;
    t.clahe = o.equalize;
    t.f_threshold = o.F_threshold;
    return t;
  }
};

}  // namespace dynavins::tracker
