#include "stages/imu/frame_imu_pairer.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <spdlog/spdlog.h>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::imu {

void append_interval(PreintegratedInterval& first, const PreintegratedInterval& later) {
  if (later.t_begin_ns != first.t_end_ns)
    throw std::invalid_argument("append_interval: interval starting at " + std::to_string(later.t_begin_ns) +
                                " ns does not continue one ending at " + std::to_string(first.t_end_ns) + " ns");
  const std::vector<ImuSample>& s = later.preint.samples;
  // s[0] is later's start, interpolated at the shared frame time: first already ends with it.
  ImuPreintegration pre(first.preint);
  for (std::size_t i = 1; i < s.size(); ++i) pre.integrate(s[i]);
  first.preint = pre.deltas();
  first.t_end_ns = later.t_end_ns;
  first.has_gap = first.has_gap || later.has_gap;
  first.max_gap_ns = std::max(first.max_gap_ns, later.max_gap_ns);
  first.num_raw_samples += later.num_raw_samples;
}

std::vector<FrameWithImu> FrameImuPairer::add_frame(TrackedFrame frame) {
  if (last_frame_in_ns_ && frame.t_ns <= *last_frame_in_ns_) {
    ++stats_.frames_out_of_order;
    spdlog::warn("FrameImuPairer: frame at {} ns ignored (not after {} ns)", frame.t_ns, *last_frame_in_ns_);
    return {};
  }
  ++stats_.frames_in;
  last_frame_in_ns_ = frame.t_ns;
  frames_.push_back(std::move(frame));
  return drain();
}

std::vector<FrameWithImu> FrameImuPairer::add_interval(PreintegratedInterval interval) {
  if (interval.t_end_ns <= interval.t_begin_ns ||
      (last_interval_end_ns_ && interval.t_begin_ns < *last_interval_end_ns_)) {
    ++stats_.intervals_out_of_order;
    spdlog::warn("FrameImuPairer: interval ({}, {}] ns ignored (out of order)", interval.t_begin_ns,
                 interval.t_end_ns);
    return {};
  }
  ++stats_.intervals_in;
  last_interval_end_ns_ = interval.t_end_ns;
  intervals_.push_back(std::move(interval));
  return drain();
}

void FrameImuPairer::finish() {
  stats_.unpaired_at_finish += static_cast<int64_t>(frames_.size());
  if (!frames_.empty())
    spdlog::warn("FrameImuPairer: {} frame(s) from {} ns on never got their IMU; not estimated", frames_.size(),
                 frames_.front().t_ns);
  frames_.clear();
  intervals_.clear();
}

void FrameImuPairer::emit(std::vector<FrameWithImu>& out, std::optional<PreintegratedInterval> imu) {
  FrameWithImu f{std::move(frames_.front()), std::move(imu)};
  frames_.pop_front();
  last_emitted_ns_ = f.frame.t_ns;
  ++stats_.emitted;
  if (f.imu) ++stats_.emitted_with_imu;
  out.push_back(std::move(f));
}

std::vector<FrameWithImu> FrameImuPairer::drain() {
  std::vector<FrameWithImu> out;
  while (!frames_.empty()) {
    if (!last_emitted_ns_) {  // the very first frame: nothing before it to integrate from
      emit(out, std::nullopt);
      continue;
    }
    const int64_t t_prev = *last_emitted_ns_, t_frame = frames_.front().t_ns;
    while (!intervals_.empty() && intervals_.front().t_end_ns <= t_prev) {
      intervals_.pop_front();
      ++stats_.intervals_discarded;
    }
    if (intervals_.empty()) break;  // the IMU has not reached past the previous frame yet
    if (intervals_.front().t_begin_ns < t_prev) {
      // The previous frame lies strictly inside this interval (it was a restart off the boundaries):
      // no part of the interval can be used from there.
      intervals_.pop_front();
      ++stats_.intervals_discarded;
      continue;
    }
    // Walk the contiguous intervals from t_prev towards the frame.
    std::size_t k = 0;
    bool hole = intervals_.front().t_begin_ns > t_prev;
    while (!hole && intervals_[k].t_end_ns < t_frame && k + 1 < intervals_.size()) {
      if (intervals_[k + 1].t_begin_ns != intervals_[k].t_end_ns) hole = true;
      else ++k;
    }
    if (hole) {
      // The IMU does not connect the previous frame to this one: hand it on as a new start.
      ++stats_.restarted_without_imu;
      spdlog::warn("FrameImuPairer: no continuous IMU from {} ns to frame {} ns; frame passed on without IMU",
                   t_prev, t_frame);
      emit(out, std::nullopt);
      continue;
    }
    if (intervals_[k].t_end_ns < t_frame) break;  // wait for more IMU
    if (intervals_[k].t_end_ns > t_frame) {
      // The frame time is no interval boundary (the IMU stage rejected it): the IMU carries on to the
      // next frame instead.
      ++stats_.skipped_inside_interval;
      spdlog::warn("FrameImuPairer: frame {} ns falls inside IMU interval ({}, {}] ns; skipped", t_frame,
                   intervals_[k].t_begin_ns, intervals_[k].t_end_ns);
      frames_.pop_front();
      continue;
    }
    PreintegratedInterval merged = std::move(intervals_.front());
    intervals_.pop_front();
    for (std::size_t i = 0; i < k; ++i) {
      append_interval(merged, intervals_.front());
      intervals_.pop_front();
    }
    stats_.merged_intervals += static_cast<int64_t>(k);
    emit(out, std::move(merged));
  }
  return out;
}

}  // namespace dynavins::imu
