#pragma once
// The features of the sliding window (VINS-Fusion's FeatureManager, redone): per feature id its
// observations in consecutive window slots, its inverse depth in the anchor (first) slot's cam0, and
// its DynaVINS weight state (w_j, w̄_j, n_j of paper eq. 10).

#include <cstdint>
#include <functional>
#include <map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "messages/tracked_frame.hpp"

namespace dynavins::estimator {

/// VINS-Fusion measures parallax and reprojection noise at this nominal focal length (FOCAL_LENGTH):
/// keyframe_parallax is in "pixels at 460" and the reprojection sqrt-information is 460 / 1.5.
inline constexpr double kNominalFocalPx = 460.0;
/// Features seen in fewer frames do not enter the BA (VINS-Fusion: used_num < 4).
inline constexpr int kMinObservationsInBa = 4;

struct FeatureObservation {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< cam0, z = 1 plane
  Eigen::Vector2d px = Eigen::Vector2d::Zero();  ///< left pixel
  bool has_right = false;
  Eigen::Vector2d xy_right = Eigen::Vector2d::Zero();  ///< cam1, z = 1 plane
  Eigen::Vector2d px_right = Eigen::Vector2d::Zero();  ///< right pixel (outputs and scoring only)
};

/// cam0 pose in the world of a window slot: (R_wc, p_wc).
struct CameraPose {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

/// A feature's observation in a keyframe that has left the window, with that keyframe's pose as the
/// estimator left it (mono track history; window_optimizer.cpp, history_inconsistent).
struct PastObservation {
  CameraPose cam;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  ///< cam0, z = 1 plane
};

struct WindowFeature {
  int64_t id = 0;
  /// Its observations in the latest keyframes that left the window, oldest first (at most
  /// WindowFeatures::max_past(); kept only when remove_oldest is asked to).
  std::vector<PastObservation> past;
  int start_slot = 0;                   ///< window slot of obs[0] (the anchor)
  std::vector<FeatureObservation> obs;  ///< obs[k] is at slot start_slot + k
  double inv_depth = 0;                 ///< 1 / z in the anchor's cam0; the BA's parameter block
  bool has_depth = false;
  double weight = 1.0;       ///< w_j (paper eq. 10), the weight the run reports and scores
  double state_weight = 1.0;  ///< ŵ_j = state_step_weight(w_j), the value the reprojection factors read
  double weight_prev = 1.0;  ///< w̄_j: weight after the previous window solve
  int times_solved = 0;      ///< n_j
  int8_t sim_label = -1;     ///< simulator label at the latest observation (scoring only)

  int end_slot() const { return start_slot + static_cast<int>(obs.size()) - 1; }
  bool in_ba() const { return has_depth && static_cast<int>(obs.size()) >= kMinObservationsInBa; }
};

using SlotCameraPose = std::function<CameraPose(int slot)>;

class WindowFeatures {
 public:
  /// Adds the tracked frame at window slot `slot` (the newest). Returns true when the previous newest
  /// frame (slot - 1) should stay as a keyframe (VINS' addFeatureCheckParallax): early in the window,
  /// few tracked or long tracks, many new features, or average parallax between slots slot-2 and slot-1
  /// of at least `min_parallax` (on the z = 1 plane).
  bool add_frame(int slot, const TrackedFrame& frame, double min_parallax, bool use_right);

  /// Sets depths of features without one: stereo triangulation in the anchor slot when it has a right
  /// observation, else two-view triangulation from the first two observations (>= 2 needed).
  /// `T_c0c1` is cam1's pose in cam0. Depths <= 0.1 m or > 1000 m are not set.
  void triangulate(const SlotCameraPose& cam, const Eigen::Isometry3d& T_c0c1, bool use_right);

  /// Drops slot 0 (after the window's oldest keyframe was marginalised): features anchored there lose
  /// their first observation and are re-anchored at the next (depth carried over through the world
  /// point); features left without observations are erased. Every slot index shifts down by one.
  /// `cam` gives the poses of the slots BEFORE the shift. With `keep_past` (and max_past() > 0) the dropped
  /// observation joins the feature's `past`, with slot 0's pose, and past_frame() becomes slot 1's.
  void remove_oldest(const SlotCameraPose& cam, bool keep_past = false);

  /// How many past observations a feature keeps (0, the default: none).
  void set_max_past(int n) { max_past_ = n; }
  int max_past() const { return max_past_; }
  /// The pose slot 0 had when the past observations were last added. The past poses are in the world as
  /// it was then; a solve moves the whole window in position and yaw before the gauge moves it back
  /// (window_gauge.hpp), so a reader maps them through slot 0's pose now against this one.
  const CameraPose& past_frame() const { return past_frame_; }
  /// Drops slot `slot` (the second newest, not kept as keyframe): its observations go, later slots shift
  /// down by one; a feature anchored there is re-anchored at the following slot.
  void remove_slot(int slot, const SlotCameraPose& cam);

  /// Erases features whose depth became invalid in the solve (behind the camera); returns how many.
  int remove_bad_depths();
  void clear() {
    features_.clear();
    past_frame_ = CameraPose{};
  }

  std::map<int64_t, WindowFeature>& all() { return features_; }
  const std::map<int64_t, WindowFeature>& all() const { return features_; }
  /// Features of the latest add_frame that were already in the window.
  int last_tracked_count() const { return last_track_num_; }

 private:
  void reanchor(WindowFeature& f, const CameraPose& old_anchor, const CameraPose& new_anchor) const;

  std::map<int64_t, WindowFeature> features_;  // node-based: inv_depth / weight addresses stay valid
  int last_track_num_ = 0;
  int max_past_ = 0;
  CameraPose past_frame_;
};

/// Linear (DLT) two-view triangulation of normalized observations x0, x1 with camera poses in a
/// common frame: (R0, p0), (R1, p1) camera-to-frame. Returns the point in that frame.
Eigen::Vector3d triangulate_two_view(const CameraPose& c0, const CameraPose& c1, const Eigen::Vector2d& x0,
                                   const Eigen::Vector2d& x1);

}  // namespace dynavins::estimator
