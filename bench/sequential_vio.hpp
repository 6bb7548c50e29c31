#pragma once
// The whole front end and estimator run one after the other on one thread, frame by frame: the
// deterministic twin of `dynavins run` (same stages, no queues), for tests and benches that must give the
// same answer every time.

#include <functional>
#include <map>
#include <vector>

#include "eval/trajectory.hpp"
#include "io/sensor_source.hpp"
#include "stages/common/estimator_options.hpp"
#include "stages/estimator/sliding_window_estimator.hpp"

namespace dynavins::bench {

/// A feature's last robust-BA weight and simulator label.
struct FeatureOutcome {
  float weight = 1.f;
  int8_t sim_label = -1;
  int times_solved = 0;
};

struct SequentialVioResult {
  eval::Trajectory estimate;      ///< body pose of every frame while tracking
  eval::Trajectory ground_truth;  ///< from the source, when it has one
  std::map<int64_t, FeatureOutcome> features;  ///< by feature id, as last seen in a window
  std::vector<double> ba_ms;       ///< per window solve (all alternations)
  std::vector<double> tracker_ms;  ///< per frame
  int frames = 0, tracking_frames = 0, resets = 0;
  std::vector<int64_t> standstill_t_ns;  ///< frames the estimator found at rest (zero-velocity factor)
  std::map<int64_t, double> true_speed;  ///< |v_wb| of the source's ground truth, when it has velocities
};

/// Runs tracker -> IMU intervals -> estimator over every event of `source`. `on_tracked`, when set, sees
/// every tracked frame right after the tracker (e.g. to score tracks against simulator truth).
SequentialVioResult runSequentialVio(io::SensorSource& source, const EstimatorOptions& options,
                                     const estimator::EstimatorMode& mode,
                                     const std::function<void(const TrackedFrame&)>& on_tracked = {});

/// Share of moving-object features (label > 0) with weight < 0.5, and of static ones (label 0) with
/// weight > 0.5, among features that went through at least one solve.
struct WeightScore {
  int moving = 0, static_ = 0;
  double moving_rejected = 0, static_kept = 0;
};
WeightScore scoreWeights(const std::map<int64_t, FeatureOutcome>& features);

}  // namespace dynavins::bench
