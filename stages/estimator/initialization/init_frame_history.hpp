#pragma once
// The frames before a mono initialisation, kept for several window lengths: every 2nd, 3rd or 4th frame of
// them spans 2-4 times the time of the latest W+1 frames in the same W+1 slots (ours, issue 23: a start
// from rest reaches parallax late, when its acceleration is nearly over).

#include <deque>
#include <optional>
#include <vector>

#include "messages/preintegrated_interval.hpp"
#include "messages/tracked_frame.hpp"

namespace dynavins::estimator {

/// One frame and the IMU from the frame before it (none for the first frame returned).
struct HistoryFrame {
  TrackedFrame frame;
  std::optional<PreintegratedInterval> imu;
};

/// Two intervals back to back (a ends where b begins) as one: b's samples integrated on after a's, as the
/// window does when it drops a frame. Throws std::invalid_argument when they do not meet.
PreintegratedInterval join_intervals(const PreintegratedInterval& a, const PreintegratedInterval& b);

/// A bounded first-in first-out store of the latest frames (images shallow) and their IMU intervals.
class InitFrameHistory {
 public:
  explicit InitFrameHistory(int capacity);

  /// Appends the newest frame and the IMU since the previous one (null for the first); drops the oldest
  /// frame beyond the capacity.
  void push(const TrackedFrame& frame, const PreintegratedInterval* imu);
  void clear() { frames_.clear(); }
  int size() const { return static_cast<int>(frames_.size()); }
  bool full() const { return size() == capacity_; }

  /// The newest frame and every `stride`-th one before it, at most `max_frames` in all (0: no limit),
  /// oldest first; each one's interval joined over the frames skipped, the first one's left empty.
  std::vector<HistoryFrame> strided(int stride, int max_frames = 0) const;

 private:
  int capacity_;
  std::deque<HistoryFrame> frames_;
};

}  // namespace dynavins::estimator
