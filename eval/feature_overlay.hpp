#pragma once
// The weighted features of a run drawn on its camera images, like Fig. 1 of the DynaVINS paper:
// features the robust BA trusts (weight >= 0.5) as green circles, rejected ones as red crosses.

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dynavins::eval {

/// One row of a run's features.csv that the overlay needs.
struct OverlayFeature {
  double u = 0.0, v = 0.0;  ///< pixel in the left image
  double weight = 1.0;      ///< w_j in [0, 1]
  int sim_label = -1;       ///< -1 unknown, 0 static, k > 0 moving object k
};

/// All features of one estimated frame.
struct FeatureFrame {
  std::int64_t t_ns = 0;
  std::int64_t seq = 0;
  std::vector<OverlayFeature> features;

  std::size_t rejected() const;  ///< weight < 0.5
  std::size_t moving() const;    ///< sim_label > 0
};

/// Weight below which a feature counts as rejected (drawn as a red cross).
constexpr double kRejectWeight = 0.5;

/// Reads features.csv as `dynavins run` writes it (header t_ns,seq,feature_id,u,v,weight,...,sim_label,...;
/// columns found by name), grouped into frames in file order. Throws std::runtime_error naming the
/// file, line and field on a missing file, a missing column or a malformed value.
std::vector<FeatureFrame> read_feature_frames(const std::string& path);

/// Picks up to `n` frames to show: the most moving features (sim_label > 0) first, ties and runs
/// without labels by the most rejected features; frames closer than `min_gap_s` to an already
/// picked one are skipped so a grid does not show one moment n times. Returned in time order.
std::vector<std::size_t> pick_overlay_frames(const std::vector<FeatureFrame>& frames, std::size_t n,
                                             double min_gap_s = 2.0);

/// Style of draw_feature_overlay().
struct OverlayStyle {
  int radius = 5;      ///< circle radius / half cross size [px]
  int thickness = 2;
  bool caption = true; ///< a dark band under the image with `caption_text`
};

/// Colours used (BGR).
inline const cv::Scalar kKeptColor{0, 255, 0};
inline const cv::Scalar kRejectedColor{0, 0, 255};

/// The image (8-bit gray or BGR) as BGR with every feature drawn: weight >= 0.5 a green circle,
/// below a red cross; features outside the image are skipped. With style.caption the picture
/// grows by a band at the bottom holding `caption_text`. Throws std::invalid_argument for an empty
/// image or one that is not 8-bit with 1 or 3 channels.
cv::Mat draw_feature_overlay(const cv::Mat& image, const std::vector<OverlayFeature>& features,
                             const std::string& caption_text = {}, const OverlayStyle& style = {});

/// "t 12.35 s | 143 features, 40 rejected (28 %) | 35 on moving objects, 33 of them rejected"
/// (the moving part only when the frame has sim labels).
std::string overlay_caption(const FeatureFrame& frame, double seconds_from_start);

/// Tiles equally sized BGR images row-major into a grid `cols` wide (empty cells black).
/// Throws std::invalid_argument when the list is empty, cols < 1 or the sizes / types differ.
cv::Mat tile_images(const std::vector<cv::Mat>& images, int cols);

}  // namespace dynavins::eval
