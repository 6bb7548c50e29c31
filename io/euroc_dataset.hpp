#pragma once
// An EuRoC ASL folder (mav0/cam0, cam1, imu0, state_groundtruth_estimate0), read as it is.
// The CSV files are read and checked when the dataset is opened (column counts, numbers,
// strictly increasing timestamps): bad input is an InputError naming the file and line. A listed
// image whose file is absent is a documented skip: counted (missing_images()) and logged with its
// line, because real EuRoC extracts do that (the shared V1_01 clip lists 4 right images it lacks). Images are decoded on demand by load(), so a long sequence costs little memory.

#include <cstdint>
#include <string>
#include <vector>

#include "messages/sensor_messages.hpp"

namespace dynavins::io {

/// One time-matched stereo pair: paths of its images (right empty for a mono folder).
struct EurocFrame {
  int64_t t_ns = 0;
  std::string left;
  std::string right;
  std::string labels;  ///< simulated data only: per-pixel moving-object label image, else empty
};

class EurocDataset {
 public:
  /// `dir` is the folder holding mav0/ (or mav0/ itself). Stereo pairs are matched by timestamp
  /// within `stereo_tolerance_ns`; images without a partner are counted, not used.
  explicit EurocDataset(const std::string& dir, int64_t stereo_tolerance_ns = 1'000'000);

  const std::vector<EurocFrame>& frames() const { return frames_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  /// Empty when the folder has no state_groundtruth_estimate0.
  const std::vector<GroundTruthState>& ground_truth() const { return ground_truth_; }
  bool stereo() const { return stereo_; }
  std::size_t unmatched_left() const { return unmatched_left_; }
  std::size_t unmatched_right() const { return unmatched_right_; }
  /// Rows of cam0/cam1 data.csv whose image file does not exist (skipped).
  std::size_t missing_images() const { return missing_images_; }
  const std::string& root() const { return mav0_; }

  /// Decodes frame `i` (8-bit gray). Throws InputError naming an unreadable image.
  StereoFrame load(std::size_t i) const;

 private:
  std::string mav0_;
  bool stereo_ = false;
  std::vector<EurocFrame> frames_;
  std::vector<ImuSample> imu_;
  std::vector<GroundTruthState> ground_truth_;
  std::size_t unmatched_left_ = 0;
  std::size_t unmatched_right_ = 0;
  std::size_t missing_images_ = 0;
};

}  // namespace dynavins::io
