#include "stages/imu/imu_interval_builder.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "stages/imu/imu_preintegration.hpp"
#include "stages/imu/imu_sample_interpolation.hpp"

namespace dynavins::imu {

ImuIntervalBuilder::ImuIntervalBuilder(ImuIntervalBuilderOptions options) : opt_(std::move(options)) {
  if (!(opt_.imu_rate_hz > 0.0) || !(opt_.gap_periods >= 1.0))
    throw std::invalid_argument("ImuIntervalBuilder: imu_rate_hz must be > 0 and gap_periods >= 1");
  gap_threshold_ns_ = std::llround(opt_.gap_periods * 1e9 / opt_.imu_rate_hz);
}

void ImuIntervalBuilder::set_biases(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) {
  ba_ = ba;
  bg_ = bg;
}

std::vector<PreintegratedInterval> ImuIntervalBuilder::add_imu(const ImuSample& s) {
  if (!imu_.empty() && s.t_ns <= imu_.back().t_ns) {
    ++stats_.imu_rejected_out_of_order;
    spdlog::debug("ImuIntervalBuilder: IMU sample at {} ns rejected (last {} ns)", s.t_ns, imu_.back().t_ns);
    return {};
  }
  imu_.push_back(s);
  return drain();
}

std::vector<PreintegratedInterval> ImuIntervalBuilder::add_frame(int64_t t_ns) {
  if (have_frame_ && t_ns <= last_frame_ns_) {
    ++stats_.frames_rejected_out_of_order;
    spdlog::warn("ImuIntervalBuilder: frame at {} ns rejected (last {} ns)", t_ns, last_frame_ns_);
    return {};
  }
  have_frame_ = true;
  last_frame_ns_ = t_ns;
  frames_.push_back(t_ns);
  return drain();
}

std::vector<PreintegratedInterval> ImuIntervalBuilder::drain() {
  std::vector<PreintegratedInterval> out;
  while (frames_.size() >= 2) {
    const int64_t t0 = frames_[0], t1 = frames_[1];
    if (imu_.empty() || imu_.back().t_ns < t1) break;  // IMU does not cover the end yet
    if (imu_.front().t_ns > t0) {
      // No sample at or before frame i: the start cannot be interpolated, and extrapolating would hide it.
      ++stats_.frames_without_imu_before;
      spdlog::warn("ImuIntervalBuilder: no IMU at or before frame {} ns; no interval starts there", t0);
      frames_.pop_front();
      continue;
    }
    out.push_back(build(t0, t1));
    if (out.back().has_gap) {
      ++stats_.intervals_with_gap;
      spdlog::warn("ImuIntervalBuilder: IMU gap of {} ms in interval [{}, {}] ns", out.back().max_gap_ns * 1e-6,
                   t0, t1);
    }
    frames_.pop_front();
  }
  trim();
  return out;
}

PreintegratedInterval ImuIntervalBuilder::build(int64_t t0, int64_t t1) const {
  // i0: last sample at or before t0 (exists, checked by drain()).
  size_t i0 = 0;
  while (i0 + 1 < imu_.size() && imu_[i0 + 1].t_ns <= t0) ++i0;
  PreintegratedInterval iv;
  iv.t_begin_ns = t0;
  iv.t_end_ns = t1;
  const ImuSample start = (imu_[i0].t_ns == t0) ? imu_[i0] : interpolate(imu_[i0], imu_[i0 + 1], t0);
  ImuPreintegration pre(start, ba_, bg_, opt_.noise);
  size_t k = i0 + 1;
  for (; k < imu_.size() && imu_[k].t_ns < t1; ++k) {
    pre.integrate(imu_[k]);
    ++iv.num_raw_samples;
  }
  // imu_[k] is the first sample at or after t1 (exists: drain() checked imu_.back() >= t1).
  pre.integrate(interpolate(imu_[k - 1], imu_[k], t1));
  iv.preint = pre.deltas();
  if (imu_[k].t_ns == t1) ++iv.num_raw_samples;
  for (size_t m = i0 + 1; m <= k; ++m) iv.max_gap_ns = std::max(iv.max_gap_ns, imu_[m].t_ns - imu_[m - 1].t_ns);
  iv.has_gap = iv.max_gap_ns > gap_threshold_ns_;
  return iv;
}

void ImuIntervalBuilder::trim() {
  // Keep the last sample at or before the oldest time still needed as an interval start.
  if (!frames_.empty() || have_frame_) {
    const int64_t need = frames_.empty() ? last_frame_ns_ : frames_.front();
    while (imu_.size() >= 2 && imu_[1].t_ns <= need) imu_.pop_front();
  }
  while (imu_.size() > opt_.max_buffered_samples) imu_.pop_front();
}

}  // namespace dynavins::imu
