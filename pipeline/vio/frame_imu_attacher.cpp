#include "pipeline/vio/frame_imu_attacher.hpp"

#include <utility>

namespace dynavins::pipeline {

std::optional<TrackerInput> FrameImuAttacher::add_imu(const ImuSample& s) {
  imu_.push_back(s);
  if (held_ && s.t_ns >= held_->t_ns) return release();
  if (!held_ && imu_.size() > max_buffered_) imu_.erase(imu_.begin(), imu_.end() - max_buffered_);
  return std::nullopt;
}

std::optional<TrackerInput> FrameImuAttacher::add_frame(StereoFrame&& f) {
  std::optional<TrackerInput> out;
  if (held_) {
    ++released_incomplete_;
    out = release();
  }
  held_ = std::move(f);
  return out;
}

std::optional<TrackerInput> FrameImuAttacher::finish() {
  if (!held_) return std::nullopt;
  ++released_incomplete_;
  return release();
}

TrackerInput FrameImuAttacher::release() {
  TrackerInput out{std::move(*held_), imu_};
  held_.reset();
  // The next interval starts at this frame: keep its last sample at or before it, and what follows.
  std::size_t keep = 0;
  while (keep + 1 < imu_.size() && imu_[keep + 1].t_ns <= out.frame.t_ns) ++keep;
  imu_.erase(imu_.begin(), imu_.begin() + static_cast<std::ptrdiff_t>(keep));
  return out;
}

}  // namespace dynavins::pipeline
