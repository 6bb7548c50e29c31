#pragma once
// The IMU stage (DESIGN.md §2): IMU samples and the time of every source frame in, one preintegrated
// interval per pair of consecutive source frames out. A thin stage object around ImuIntervalBuilder that
// takes its settings from the loaded yaml and counts what it saw. No threads.

#include <cstdint>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "messages/sensor_messages.hpp"
#include "stages/common/estimator_options.hpp"
#include "stages/imu/imu_interval_builder.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::imu {

/// The capture time of one source frame: where an IMU interval ends and the next begins.
struct FrameTime {
  int64_t t_ns = 0;
};

/// What the IMU stage consumes: the replay driver sends both, in its time order.
using ImuStageInput = std::variant<ImuSample, FrameTime>;

/// How the yaml's acc_n / gyr_n / acc_w / gyr_w are read.
enum class ImuNoiseConvention {
  /// Used as given, exactly as VINS-Fusion's IntegrationBase does (its configs are tuned for this).
  VinsFusion,
  /// Continuous-time (Kalibr) densities, mapped with ImuNoiseParams::from_continuous_densities at imu_rate_hz.
  ContinuousDensity,
};

/// Settings of ImuStage.
struct ImuStageOptions {
  double imu_rate_hz = 200.0;  ///< nominal rate: gap threshold and the density mapping
  double gap_periods = 3.0;    ///< a sample spacing above gap_periods / imu_rate_hz flags the interval
  ImuNoiseParams noise;        ///< preintegration noise, VINS-Fusion convention

  /// Noise from the yaml's IMU keys read with `convention`; throws std::invalid_argument on a
  /// non-positive rate.
  static ImuStageOptions from(const EstimatorOptions& o, double imu_rate_hz = 200.0,
                              ImuNoiseConvention convention = ImuNoiseConvention::VinsFusion);
};

/// Counters for the run summary.
struct ImuStageStats {
  int64_t imu_samples = 0;   ///< IMU samples received
  int64_t frame_times = 0;   ///< frame times received
  int64_t intervals = 0;     ///< intervals emitted
  int64_t bias_updates = 0;  ///< set_biases() calls that changed the biases
};

class ImuStage {
 public:
  explicit ImuStage(const ImuStageOptions& options);

  /// Feeds one sample or frame time; returns the intervals completed by it (often none).
  std::vector<PreintegratedInterval> process(const ImuStageInput& input);

  /// Linearisation biases for intervals built from now on (the estimator's latest estimate).
  void set_biases(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg);

  const ImuStageStats& stats() const { return stats_; }
  /// Rejected input and gap counters of the interval builder.
  const ImuIntervalBuilderStats& builder_stats() const { return builder_.stats(); }

 private:
  ImuIntervalBuilder builder_;
  ImuStageStats stats_;
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero(), bg_ = Eigen::Vector3d::Zero();
};

}  // namespace dynavins::imu
