#pragma once
// Hands the tracker thread the gyro samples of each frame interval without sharing anything: the
// replay thread, which sees the IMU and the frames in time order, packs into each frame the samples
// from the last one at or before the previous frame to the first one at or after this frame. A frame
// is held back until that last sample has arrived (one IMU period, ~5 ms of sensor time: the IMU stage
// waits for the same sample to close the frame's interval), so both ends can be interpolated.
//
// The samples are those since the previous frame *handed over*, not the previous frame *tracked*: when
// the frame queue drops a frame (paced runs), the next one's samples start after the tracker's previous
// frame and GyroRotationPredictor refuses them. Plain object, no threads.

#include <cstddef>
#include <optional>
#include <vector>

#include "messages/sensor_messages.hpp"

namespace dynavins::pipeline {

/// What the tracker thread consumes: a frame and the IMU samples around its interval (possibly none).
struct TrackerInput {
  StereoFrame frame;
  std::vector<ImuSample> imu;
  /// How many of the frames before this one the estimator can finish with the data sent before it (an IMU
  /// sample at or after their time came first: their interval is complete); -1: unknown. At rate 0 the
  /// tracker waits for the estimator's verdict on those (RejectedTracksFeedback), never on a frame whose
  /// IMU lies behind an outage still to be replayed.
  int64_t finishable_before = -1;
};

class FrameImuAttacher {
 public:
  /// `max_buffered`: while no frame comes (camera outage) only the newest this many samples are kept.
  explicit FrameImuAttacher(std::size_t max_buffered = 4000) : max_buffered_(max_buffered) {}

  /// An IMU sample; returns the held frame when the sample reaches its time.
  std::optional<TrackerInput> add_imu(const ImuSample& s);
  /// A new frame, which is held; returns the frame held before it, if no sample had reached that one's
  /// time (it goes with the samples there are, and the predictor will refuse them).
  std::optional<TrackerInput> add_frame(StereoFrame&& f);
  /// End of input: the held frame, if any.
  std::optional<TrackerInput> finish();

  /// Frames handed over before an IMU sample had reached their time.
  std::size_t released_incomplete() const { return released_incomplete_; }

 private:
  TrackerInput release();

  std::size_t max_buffered_;
  std::vector<ImuSample> imu_;  // from the last sample at or before the previous frame on
  std::optional<StereoFrame> held_;
  std::size_t released_incomplete_ = 0;
};

}  // namespace dynavins::pipeline
