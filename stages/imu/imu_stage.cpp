#include "stages/imu/imu_stage.hpp"

#include <stdexcept>
#include <string>

namespace dynavins::imu {

ImuStageOptions ImuStageOptions::from(const EstimatorOptions& o, double imu_rate_hz, ImuNoiseConvention convention) {
  if (!(imu_rate_hz > 0.0))
    throw std::invalid_argument("IMU rate must be positive, got " + std::to_string(imu_rate_hz) + " Hz");
  ImuStageOptions s;
  s.imu_rate_hz = imu_rate_hz;
  if (convention == ImuNoiseConvention::ContinuousDensity) {
    s.noise = ImuNoiseParams::from_continuous_densities(o.acc_n, o.gyr_n, o.acc_w, o.gyr_w, 1.0 / imu_rate_hz);
  } else {
    s.noise.acc_n = o.acc_n;
    s.noise.gyr_n = o.gyr_n;
    s.noise.acc_w = o.acc_w;
    s.noise.gyr_w = o.gyr_w;
  }
  return s;
}

namespace {
ImuIntervalBuilderOptions builder_options(const ImuStageOptions& o) {
  ImuIntervalBuilderOptions b;
  b.imu_rate_hz = o.imu_rate_hz;
  b.gap_periods = o.gap_periods;
  b.noise = o.noise;
  return b;
}
}  // namespace

ImuStage::ImuStage(const ImuStageOptions& options) : builder_(builder_options(options)) {}

std::vector<PreintegratedInterval> ImuStage::process(const ImuStageInput& input) {
  std::vector<PreintegratedInterval> out;
  if (const auto* s = std::get_if<ImuSample>(&input)) {
    ++stats_.imu_samples;
    out = builder_.add_imu(*s);
  } else {
    ++stats_.frame_times;
    out = builder_.add_frame(std::get<FrameTime>(input).t_ns);
  }
  stats_.intervals += static_cast<int64_t>(out.size());
  return out;
}

void ImuStage::set_biases(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) {
  if (ba == ba_ && bg == bg_) return;
  ba_ = ba;
  bg_ = bg;
  builder_.set_biases(ba, bg);
  ++stats_.bias_updates;
}

}  // namespace dynavins::imu
