#include "io/euroc_source.hpp"

#include <algorithm>
#include <limits>

#include <spdlog/spdlog.h>

namespace dynavins::io {
namespace {

/// [begin, end) of the items of `v` whose time lies in [t0, t1].
template <typename T>
std::pair<std::size_t, std::size_t> span_of(const std::vector<T>& v, int64_t t0, int64_t t1) {
  const auto lo = std::lower_bound(v.begin(), v.end(), t0, [](const T& x, int64_t t) { return x.t_ns < t; });
  const auto hi = std::upper_bound(v.begin(), v.end(), t1, [](int64_t t, const T& x) { return t < x.t_ns; });
  return {static_cast<std::size_t>(lo - v.begin()), static_cast<std::size_t>(hi - v.begin())};
}

}  // namespace

EurocSource::EurocSource(std::shared_ptr<const EurocDataset> data, int64_t margin_ns) : data_(std::move(data)) {
  const int64_t t0 = data_->frames().front().t_ns - margin_ns;
  const int64_t t1 = data_->frames().back().t_ns + margin_ns;
  std::tie(imu_, imu_end_) = span_of(data_->imu(), t0, t1);
  std::tie(gt_, gt_end_) = span_of(data_->ground_truth(), t0, t1);
  const std::size_t skipped = data_->imu().size() - (imu_end_ - imu_);
  if (skipped)
    spdlog::info("{}: {} IMU samples outside the images' time span (+-{:.1f} s) are not replayed", data_->root(),
                 skipped, margin_ns / 1e9);
  if (imu_end_ == imu_) spdlog::warn("{}: no IMU sample within the images' time span", data_->root());
}

bool EurocSource::next(SensorEvent& out) {
  constexpr int64_t kNone = std::numeric_limits<int64_t>::max();
  const int64_t tf = frame_ < data_->frames().size() ? data_->frames()[frame_].t_ns : kNone;
  const int64_t ti = imu_ < imu_end_ ? data_->imu()[imu_].t_ns : kNone;
  const int64_t tg = gt_ < gt_end_ ? data_->ground_truth()[gt_].t_ns : kNone;
  if (tf == kNone && ti == kNone && tg == kNone) return false;
  // At equal times the IMU goes first: a frame's preintegration needs the sample at its stamp.
  if (ti <= tf && ti <= tg) {
    out = data_->imu()[imu_++];
  } else if (tg <= tf) {
    out = data_->ground_truth()[gt_++];
  } else {
    out = data_->load(frame_++);
  }
  return true;
}

double EurocSource::progress() const {
  return static_cast<double>(frame_) / static_cast<double>(data_->frames().size());
}

std::string EurocSource::describe() const {
  return data_->root() + " (EuRoC, " + std::to_string(data_->frames().size()) +
         (data_->stereo() ? " stereo frames)" : " mono frames)");
}

}  // namespace dynavins::io
