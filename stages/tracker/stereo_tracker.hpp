#pragma once
// Stereo KLT front end (VINS-Fusion's feature tracker, redone): pyramidal Lucas-Kanade on the left
// image with a forward-backward check, Shi-Tomasi corners under a min-distance mask that keeps the
// longest tracks, left-to-right KLT with a reverse check for the stereo observation.
// Moving objects are tracked like the rest: rejecting them is the estimator's job.

#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/imgproc.hpp>

#include "messages/sensor_messages.hpp"
#include "messages/tracked_frame.hpp"
#include "stages/common/camera_model.hpp"
#include "stages/tracker/corner_detector.hpp"
#include "stages/tracker/patch_template.hpp"
#include "stages/tracker/tracker_options.hpp"

namespace dynavins::tracker {

class StereoTracker {
 public:
  /// `cam1` may be null for mono use; then a frame with a right image throws std::invalid_argument.
  StereoTracker(const TrackerOptions& options, CameraModelPtr cam0, CameraModelPtr cam1 = nullptr);
  // Movable, not copyable: a copy would share the image buffers both reuse in place.
  StereoTracker(const StereoTracker&) = delete;
  StereoTracker& operator=(const StereoTracker&) = delete;
  StereoTracker(StereoTracker&&) = default;
  StereoTracker& operator=(StereoTracker&&) = default;

  /// Tracks `frame` (8-bit gray left, optional right). `R_prev_curr_cam0`, the rotation of the
  /// current cam0 frame expressed in the previous one (from the gyro), seeds each KLT with the
  /// rotation-predicted pixel; a track that fails from there is retried from its old pixel.
  /// Throws std::invalid_argument on a non-gray or wrongly sized image.
  TrackedFrame process(const StereoFrame& frame, std::optional<Eigen::Matrix3d> R_prev_curr_cam0 = {});

  /// The tracks the estimator has rejected (ids, any order; applies from the next process()). They are
  /// still tracked and handed on, but do not count against `max_cnt` (at most `max_cnt` of them beside
  /// it), and one with another rejected track within 4 min_dist (part of a moving object) keeps fresh
  /// corners 2 min_dist away instead of one: a truck leading the camera otherwise holds half of the
  /// budget, and the corners born on it are trusted until the weights have seen them move
  /// (bench/results/seed_sweep.md, stop 44).
  void set_rejected(std::vector<int64_t> ids);

  /// Forgets every track (ids keep increasing).
  void reset();

  const TrackerOptions& options() const { return opt_; }

 private:
  using Pyramid = std::vector<cv::Mat>;
  struct Track {
    int64_t id;
    int length;
    cv::Point2f px;
    Eigen::Vector3d bearing;
    /// Right pixel minus left pixel at the last stereo match (NaN when the last frame had none):
    /// the disparity changes little between frames, so it seeds the next left-right KLT.
    cv::Point2f stereo_offset{std::numeric_limits<float>::quiet_NaN(), 0.f};
    int stereo_wait = 0;  ///< frames left before an unmatched track searches the right image again
    std::shared_ptr<const PatchTemplate> patch;  ///< first appearance (null: no refinement)
    AffineWarp warp;                              ///< where `patch` lay in the last frame
  };

  /// Checks type and size against the calibration (errors name the frame time and which image).
  cv::Mat prepare(const cv::Mat& img, const char* which, int64_t t_ns) const;
  void pyramid(const cv::Mat& img, Pyramid& pyr) const;
  std::vector<Track> track_temporal(const Pyramid& curr, const std::optional<Eigen::Matrix3d>& R_prev_curr,
                                    std::vector<cv::Point2f>& prev_px, TrackerStats& stats) const;
  void refine_with_patches(const cv::Mat& img, std::vector<Track>& tracks, std::vector<cv::Point2f>& prev_px,
                           TrackerStats& stats) const;
  void reject_with_f(std::vector<Track>& tracks, std::vector<cv::Point2f>& prev_px, TrackerStats& stats) const;
  void match_stereo(const Pyramid& left, const cv::Mat& right, std::vector<Track>& tracks, TrackedFrame& out);
  void enforce_spacing_and_detect(const cv::Mat& img, std::vector<Track>& tracks, std::vector<cv::Point2f>& prev_px,
                                  TrackerStats& stats);
  bool in_border(const cv::Point2f& p, const cv::Size& size) const;

  TrackerOptions opt_;
  CameraModelPtr cam0_, cam1_;
  cv::Ptr<cv::CLAHE> clahe_;
  Pyramid prev_pyr_;
  // Buffers reused from frame to frame (image-sized: allocating them afresh costs page faults).
  Pyramid curr_pyr_, right_pyr_;  ///< curr_pyr_ swaps with prev_pyr_ at the end of a frame
  cv::Mat right_scaled_, mask_;
  CornerScratch corner_scratch_;
  std::vector<Track> tracks_;
  std::vector<int64_t> rejected_;  ///< sorted (set_rejected)
  int64_t prev_t_ns_ = 0;
  int64_t next_id_ = 0;
};

}  // namespace dynavins::tracker
