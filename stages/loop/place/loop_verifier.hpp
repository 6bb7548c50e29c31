#pragma once
// Geometric verification of a loop candidate (paper IV; DESIGN.md §3): the candidate's (match's) 3-D points,
// moved into its camera frame with its pose and extrinsic, are matched by descriptor to the query's
// undistorted normalised coordinates and fed to PnP RANSAC (cv::solvePnPRansac, identity K). At least 15
// inliers and a plausible relative pose make a VerifiedLoop, whose T_m^k (eq. 13) is body to body. The PnP
// pose is refined over the inliers with the query's own 3-D points as well (two_way_refinement.hpp).

#include <string>

#include "messages/keyframe.hpp"
#include "stages/loop/place/descriptor_matching.hpp"
#include "stages/loop/place/keyframe_descriptors.hpp"

namespace dynavins::loop {

struct LoopVerifierOptions {
  DescriptorMatchOptions matching;
  double focal_px = 460.0;       // converts the pixel threshold to normalised units (EuRoC cam0 ~458 px)
  double reprojection_px = 3.0;  // RANSAC inlier threshold [px]
  int ransac_iterations = 200;
  double ransac_confidence = 0.99;
  int min_inliers = 15;             // DESIGN.md §3
  double max_translation_m = 10.0;  // |p_mq| above this is implausible for a revisit seen by the same camera
  double max_rotation_deg = 45.0;   // rotation angle of q_mq above this is implausible (VINS-Mono: 30 deg yaw)
  bool two_way_refinement = true;   // refine PnP's pose with the query's own 3-D points too (two_way_refinement.hpp)
};

enum class LoopRejection { None, TooFewMatches, PnpFailed, TooFewInliers, Implausible };

const char* to_string(LoopRejection r);

struct LoopVerification {
  bool accepted = false;
  LoopRejection rejection = LoopRejection::None;
  int matches = 0;    // putative descriptor matches
  int inliers = 0;    // PnP RANSAC inliers (also loop.inliers when accepted)
  VerifiedLoop loop;  // query_t_ns / match_t_ns always set; the pose when PnP succeeded
};

class LoopVerifier {
 public:
  explicit LoopVerifier(const LoopVerifierOptions& opts = {}) : opts_(opts) {}

  /// Verifies that `query` (C_k, the newer keyframe) sees the place of `match` (C_m, the candidate).
  LoopVerification verify(const KeyframeDescriptors& query, const KeyframeDescriptors& match) const;

  const LoopVerifierOptions& options() const { return opts_; }

 private:
  LoopVerifierOptions opts_;
};

}  // namespace dynavins::loop
