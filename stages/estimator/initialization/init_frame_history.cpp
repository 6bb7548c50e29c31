#include "stages/estimator/initialization/init_frame_history.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

PreintegratedInterval join_intervals(const PreintegratedInterval& a, const PreintegratedInterval& b) {
  if (a.t_end_ns != b.t_begin_ns) {
    throw std::invalid_argument("join_intervals: the first interval ends at " + std::to_string(a.t_end_ns) +
                                " ns, the second begins at " + std::to_string(b.t_begin_ns) + " ns");
  }
  imu::ImuPreintegration joined(a.preint);
  // b's first sample is the one interpolated at the shared frame time: a's last sample already.
  for (size_t k = 1; k < b.preint.samples.size(); ++k) joined.integrate(b.preint.samples[k]);
  PreintegratedInterval out;
  out.t_begin_ns = a.t_begin_ns;
  out.t_end_ns = b.t_end_ns;
  out.preint = joined.deltas();
  out.has_gap = a.has_gap || b.has_gap;
  out.max_gap_ns = std::max(a.max_gap_ns, b.max_gap_ns);
  out.num_raw_samples = a.num_raw_samples + b.num_raw_samples;
  return out;
}

InitFrameHistory::InitFrameHistory(int capacity) : capacity_(capacity) {
  if (capacity < 1) throw std::invalid_argument("InitFrameHistory: capacity must be at least 1");
}

void InitFrameHistory::push(const TrackedFrame& frame, const PreintegratedInterval* imu) {
  HistoryFrame h;
  h.frame = frame;
  if (imu) h.imu = *imu;
  frames_.push_back(std::move(h));
  while (size() > capacity_) frames_.pop_front();
}

std::vector<HistoryFrame> InitFrameHistory::strided(int stride, int max_frames) const {
  if (stride < 1) throw std::invalid_argument("InitFrameHistory::strided: stride must be at least 1");
  if (max_frames < 0) throw std::invalid_argument("InitFrameHistory::strided: max_frames must not be negative");
  std::vector<HistoryFrame> out;
  if (frames_.empty()) return out;
  const int newest = size() - 1;
  int first = newest;
  for (int n = 1; first - stride >= 0 && (max_frames == 0 || n < max_frames); ++n) first -= stride;
  for (int i = first; i <= newest; i += stride) {
    HistoryFrame h;
    h.frame = frames_[i].frame;
    if (i > first) {
      for (int k = i - stride + 1; k <= i; ++k) {
        if (!frames_[k].imu) throw std::logic_error("InitFrameHistory: a frame after the first has no IMU");
        h.imu = h.imu ? join_intervals(*h.imu, *frames_[k].imu) : *frames_[k].imu;
      }
    }
    out.push_back(std::move(h));
  }
  return out;
}

}  // namespace dynavins::estimator
