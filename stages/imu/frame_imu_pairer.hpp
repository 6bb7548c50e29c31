#pragma once
// Pairs each tracked frame with the IMU since the previous frame handed to the estimator.
//
// Tracked frames (tracker thread) and preintegrated intervals (IMU thread) reach the estimator through
// one fan-in queue, in whatever relative order the two threads deliver them. The IMU stage cuts one
// interval per pair of consecutive SOURCE frames, contiguous and in order; the tracker may have dropped
// some of those frames (real-time replay), so the interval of a tracked frame is the merge of the
// consecutive source intervals since the previous emitted frame. Emission is in time order.
//
// Frames that cannot be paired are never dropped silently:
//  - the IMU does not reach back to the previous emitted frame (the interval stream starts later or
//    has a hole): the frame is emitted without IMU, as a new start (`restarted_without_imu`);
//  - the frame time falls strictly inside an interval (the IMU stage rejected that frame time): the
//    frame is skipped and counted (`skipped_inside_interval`); the IMU carries over to the next frame;
//  - at finish(), frames no IMU reached yet are counted (`unpaired_at_finish`).
// No threads.

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "messages/tracked_frame.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::imu {

/// A tracked frame and the IMU over (previous emitted frame time, frame.t_ns]; no IMU for the first frame.
struct FrameWithImu {
  TrackedFrame frame;
  std::optional<PreintegratedInterval> imu;
};

/// Counters for the run summary.
struct FrameImuPairerStats {
  int64_t frames_in = 0;
  int64_t intervals_in = 0;
  int64_t emitted = 0;                  ///< frames handed on (with or without IMU)
  int64_t emitted_with_imu = 0;
  int64_t merged_intervals = 0;         ///< source intervals folded into a longer one (dropped frames)
  int64_t intervals_discarded = 0;      ///< intervals ending at or before the previous emitted frame
  int64_t frames_out_of_order = 0;      ///< frames not after the last frame received (ignored)
  int64_t intervals_out_of_order = 0;   ///< intervals not after the last interval received (ignored)
  int64_t restarted_without_imu = 0;    ///< later frames emitted without IMU: the interval stream had a hole
  int64_t skipped_inside_interval = 0;  ///< frames whose time is no interval boundary (not emitted)
  int64_t unpaired_at_finish = 0;       ///< frames waiting for IMU when the stream ended (not emitted)
};

/// Merges `later` (which must start where `first` ends) into `first`: the deltas continue with later's
/// samples after its first one (first's interpolated end), gap flags OR-ed, raw sample counts summed.
/// Throws std::invalid_argument when the two are not contiguous.
void append_interval(PreintegratedInterval& first, const PreintegratedInterval& later);

class FrameImuPairer {
 public:
  /// A tracked frame in; returns the frames that became ready (in time order).
  std::vector<FrameWithImu> add_frame(TrackedFrame frame);
  /// An interval in; returns the frames that became ready (in time order).
  std::vector<FrameWithImu> add_interval(PreintegratedInterval interval);
  /// End of both streams: counts the frames still waiting as unpaired (logged), emits nothing.
  void finish();

  const FrameImuPairerStats& stats() const { return stats_; }
  /// Frames waiting for their IMU.
  std::size_t waiting_frames() const { return frames_.size(); }

 private:
  std::vector<FrameWithImu> drain();
  void emit(std::vector<FrameWithImu>& out, std::optional<PreintegratedInterval> imu);

  std::deque<TrackedFrame> frames_;
  std::deque<PreintegratedInterval> intervals_;
  std::optional<int64_t> last_emitted_ns_;
  std::optional<int64_t> last_frame_in_ns_, last_interval_end_ns_;
  FrameImuPairerStats stats_;
};

}  // namespace dynavins::imu
