#pragma once
// The files of one `dynavins run`, in its output directory:
//   odometry.tum          one line per Tracking frame: `t x y z qx qy qz qw` (t in s, 9 decimals; evo reads it)
//   features.csv          the window's features with their robust-BA weights, per Tracking estimate
//   estimator_events.csv  t_ns, seq, event for every estimate with a non-empty event
//   groundtruth.tum       the source's ground truth, when it has one
//   summary.json          counts, per-stage timing, tracker gyro prediction, BA cost, real-time factor, memory,
//                         ATE when known
// Everything is written under a `.partial` name and renamed only by complete(): a failed or killed run
// leaves no file that looks finished.

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "eval/trajectory.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "messages/window_estimate.hpp"

namespace dynavins::pipeline {

/// What the run was, for summary.json.
struct RunDescription {
  std::string config_path;
  std::string input;     ///< e.g. "euroc:/data/V1_01"
  std::string ba_loss;   ///< "huber" / "dynavins"
  bool stereo = true;
  double rate = 0.0;
};

/// What the summary reports about the estimates; filled while they are written.
struct EstimateTotals {
  int64_t estimates = 0, tracking = 0, resets = 0, events = 0, feature_rows = 0;
  int64_t standstill = 0;            ///< estimates found at rest (zero-velocity factor)
  std::vector<double> ba_ms;         ///< per estimate with alternations > 0
  std::vector<int> alternations;     ///< same estimates
  std::vector<double> frame_ms;          ///< the estimator's whole time per frame (every estimate)
  std::vector<double> marginalization_ms;  ///< per estimate that slid the window
};

/// Accuracy against ground truth, when there is one (absent: has_gt or evaluated false).
struct AteResult {
  bool evaluated = false;
  double se3_m = 0.0, sim3_m = 0.0;  ///< RMSE of the translation error after alignment
  std::size_t matched = 0;           ///< associated pose pairs
  std::string error;                 ///< why it could not be evaluated (empty if evaluated or no GT)
};

class RunOutputs {
 public:
  /// Creates `dir` if needed, removes earlier results of the same names, opens the .partial files.
  /// Throws std::runtime_error naming the path when it cannot.
  explicit RunOutputs(const std::string& dir);
  ~RunOutputs();  ///< closes the files; .partial files of an incomplete run stay (for inspection)
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;

  /// Appends one estimate to the files (writer thread). Throws std::runtime_error on I/O failure.
  void write(const estimator::WindowEstimate& e);

  /// Writes groundtruth.tum (if any) and summary.json, evaluates ATE, flushes and renames every file to
  /// its final name. Throws std::runtime_error on I/O failure (no file is renamed then).
  void complete(const VioRunResult& run, const RunDescription& what);

  const std::string& dir() const { return dir_; }
  const EstimateTotals& totals() const { return totals_; }
  /// Filled by complete(): the odometry's ATE, and trajectory.tum's (with loop closure on).
  const AteResult& ate() const { return ate_; }
  const AteResult& trajectory_ate() const { return trajectory_ate_; }
  /// Filled by complete(): the summary.json text.
  const std::string& summary_json() const { return summary_; }

 private:
  std::string path(const std::string& name) const;
  void check(std::ofstream& f, const std::string& name) const;

  std::string dir_;
  std::ofstream odometry_, features_, events_;
  EstimateTotals totals_;
  eval::Trajectory estimated_;  // the odometry, kept for the ATE
  AteResult ate_, trajectory_ate_;
  std::string summary_;
  std::vector<std::string> written_;  // final names of the files to rename
};

/// `t_ns` as seconds with exactly 9 decimals, without floating-point rounding.
std::string format_seconds(int64_t t_ns);

/// Builds summary.json's text from the run and what was written.
std::string summary_json(const VioRunResult& run, const RunDescription& what, const EstimateTotals& totals,
                        const AteResult& ate, int64_t odometry_lines, bool has_ground_truth);

}  // namespace dynavins::pipeline
