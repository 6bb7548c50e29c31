#pragma once
// An EuRoC folder as a time-ordered SensorSource: stereo frames, IMU and ground truth merged.
// IMU and ground truth are replayed only over the image time span (plus `margin`): EuRoC folders
// can hold minutes of IMU beyond the images (the shared V1_01 clip does), which no estimator uses.

#include <memory>

#include "io/euroc_dataset.hpp"
#include "io/sensor_source.hpp"

namespace dynavins::io {

class EurocSource final : public SensorSource {
 public:
  EurocSource(std::shared_ptr<const EurocDataset> data, int64_t margin_ns = 1'000'000'000);
  bool next(SensorEvent& out) override;
  double progress() const override;
  std::string describe() const override;

 private:
  std::shared_ptr<const EurocDataset> data_;
  std::size_t frame_ = 0, imu_ = 0, gt_ = 0;
  std::size_t imu_end_ = 0, gt_end_ = 0;
};

}  // namespace dynavins::io
