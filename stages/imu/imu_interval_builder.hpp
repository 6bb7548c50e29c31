#pragma once
// Cuts the IMU stream into one preintegrated interval per pair of consecutive frames.
// Fed IMU samples and frame timestamps in any interleaving; an interval (t_i, t_j] is emitted as soon as an IMU
// sample at or after t_j has arrived. The ends are samples linearly interpolated at t_i and t_j.
// IMU samples not strictly after the last accepted one are rejected and counted. A spacing of consecutive
// samples above the gap threshold (default 3 nominal periods: one or two lost samples are normal jitter on
// USB IMUs, more is an outage) is not hidden: the interval is still emitted, flagged with the gap length,
// and the estimator decides (e.g. drop the IMU factor).

#include <cstdint>
#include <deque>
#include <vector>

#include <Eigen/Core>

#include "messages/sensor_messages.hpp"
#include "stages/imu/imu_noise_params.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::imu {

/// Settings of ImuIntervalBuilder.
struct ImuIntervalBuilderOptions {
  double imu_rate_hz = 200.0;       ///< nominal IMU rate, for the gap threshold
  double gap_periods = 3.0;         ///< a spacing > gap_periods / imu_rate_hz is a gap
  size_t max_buffered_samples = 20000;  ///< oldest samples dropped beyond this while no frame needs them
  ImuNoiseParams noise;             ///< noise for the preintegration
};

/// Counters of rejected or unusable input.
struct ImuIntervalBuilderStats {
  int64_t imu_rejected_out_of_order = 0;  ///< IMU samples with t_ns <= the last accepted one
  int64_t frames_rejected_out_of_order = 0;  ///< frame times <= the last accepted one
  int64_t frames_without_imu_before = 0;  ///< frames dropped as interval start: no IMU sample at or before them
  int64_t intervals_with_gap = 0;         ///< emitted intervals flagged has_gap
};

/// Builds PreintegratedIntervals from an IMU stream and frame times.
class ImuIntervalBuilder {
 public:
  explicit ImuIntervalBuilder(ImuIntervalBuilderOptions options = {});

  /// Sets the linearisation biases for intervals built from now on (the estimator's latest estimate).
  void set_biases(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg);

  /// Adds an IMU sample; returns the intervals it completes (possibly none). Rejects (and counts) samples
  /// not strictly after the last accepted one.
  std::vector<PreintegratedInterval> add_imu(const ImuSample& s);
  /// Adds a frame time; returns the intervals that can be completed now. Rejects (and counts) times not
  /// strictly after the last accepted frame.
  std::vector<PreintegratedInterval> add_frame(int64_t t_ns);

  /// Gap threshold in use [ns].
  int64_t gap_threshold_ns() const { return gap_threshold_ns_; }
  /// Rejection counters.
  const ImuIntervalBuilderStats& stats() const { return stats_; }

 private:
  std::vector<PreintegratedInterval> drain();
  PreintegratedInterval build(int64_t t0, int64_t t1) const;
  void trim();

  ImuIntervalBuilderOptions opt_;
  int64_t gap_threshold_ns_;
  ImuIntervalBuilderStats stats_;
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero(), bg_ = Eigen::Vector3d::Zero();
  std::deque<ImuSample> imu_;      // accepted samples still needed
  std::deque<int64_t> frames_;     // frame times whose interval to the next frame is not yet emitted
  bool have_frame_ = false;
  int64_t last_frame_ns_ = 0;
};

}  // namespace dynavins::imu
