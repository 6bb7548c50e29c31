#include "pipeline/vio/run_outputs.hpp"

#include "pipeline/vio/loop_outputs.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "eval/evaluation.hpp"
#include "pipeline/report_format.hpp"
#include "pipeline/vio/process_memory.hpp"

namespace dynavins::pipeline {
namespace fs = std::filesystem;
namespace {

const char* const kOdometry = "odometry.tum";
const char* const kFeatures = "features.csv";
const char* const kEvents = "estimator_events.csv";
const char* const kGroundTruth = "groundtruth.tum";
const char* const kSummary = "summary.json";
const char* const kTrajectory = "trajectory.tum";
const char* const kLoops = "loops.csv";
const char* const kPartial = ".partial";

// A JSON number; NaN / inf have no JSON form and become null.
std::string num(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// Nearest-rank percentile (0 for no data).
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

// An event text as one CSV field: quoted, inner quotes doubled, newlines flattened.
std::string csv_field(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += "\"\"";
    else if (c == '\n' || c == '\r') out += ' ';
    else out += c;
  }
  return out + "\"";
}

std::string tum_line(int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", format_seconds(t_ns).c_str(), p.x(),
                p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
  return buf;
}

AteResult evaluate_ate(const eval::Trajectory& gt, const eval::Trajectory& est) {
  AteResult a;
  try {
    eval::EvalOptions o;
    o.align = eval::Alignment::SE3;
    const eval::EvalResult se3 = eval::evaluate(gt, est, o);
    o.align = eval::Alignment::Sim3;
    const eval::EvalResult sim3 = eval::evaluate(gt, est, o);
    a.evaluated = true;
    a.se3_m = se3.ate.rmse;
    a.sim3_m = sim3.ate.rmse;
    a.matched = se3.ate.count;
  } catch (const std::exception& e) {
    a.error = e.what();
  }
  return a;
}

}  // namespace

std::string format_seconds(int64_t t_ns) {
  const bool neg = t_ns < 0;
  const unsigned long long a =
      neg ? static_cast<unsigned long long>(-(t_ns + 1)) + 1 : static_cast<unsigned long long>(t_ns);
  char buf[48];
  std::snprintf(buf, sizeof buf, "%s%llu.%09llu", neg ? "-" : "", a / 1'000'000'000ULL, a % 1'000'000'000ULL);
  return buf;
}

RunOutputs::RunOutputs(const std::string& dir) : dir_(dir) {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_)) throw std::runtime_error(dir_ + ": cannot create the output directory: " + ec.message());
  // Results of an earlier run in the same place would look like this run's if it fails.
  for (const char* name : {kOdometry, kFeatures, kEvents, kGroundTruth, kSummary, kTrajectory, kLoops}) {
    fs::remove(path(name), ec);
    fs::remove(path(name) + kPartial, ec);
  }
  auto open = [this](std::ofstream& f, const char* name) {
    f.open(path(name) + kPartial, std::ios::out | std::ios::trunc);
    check(f, name);
    written_.push_back(name);
  };
  open(odometry_, kOdometry);
  open(features_, kFeatures);
  open(events_, kEvents);
  odometry_ << "# t[s] x y z qx qy qz qw (body in world, Tracking frames only)\n";
  features_ << "t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z,u_r,v_r\n";
  events_ << "t_ns,seq,event\n";
}

RunOutputs::~RunOutputs() = default;

std::string RunOutputs::path(const std::string& name) const { return (fs::path(dir_) / name).string(); }

void RunOutputs::check(std::ofstream& f, const std::string& name) const {
  if (!f) throw std::runtime_error(path(name) + kPartial + ": cannot write");
}

void RunOutputs::write(const estimator::WindowEstimate& e) {
  ++totals_.estimates;
  if (e.status == estimator::EstimatorStatus::Reset) ++totals_.resets;
  if (e.standstill) ++totals_.standstill;
  totals_.frame_ms.push_back(e.solve.total_ms);
  if (e.solve.marginalization_ms > 0) totals_.marginalization_ms.push_back(e.solve.marginalization_ms);
  if (e.solve.alternations > 0) {
    totals_.ba_ms.push_back(e.solve.ba_ms);
    totals_.alternations.push_back(e.solve.alternations);
  }
  if (!e.event.empty()) {
    ++totals_.events;
    events_ << e.t_ns << ',' << e.seq << ',' << csv_field(e.event) << '\n';
    check(events_, kEvents);
  }
  if (e.status != estimator::EstimatorStatus::Tracking) return;
  ++totals_.tracking;
  odometry_ << tum_line(e.t_ns, e.state.p_wb, e.state.q_wb);
  check(odometry_, kOdometry);
  estimated_.poses.push_back(eval::stamped_pose(e.t_ns, e.state.p_wb, e.state.q_wb));
  char buf[320];
  for (const WeightedFeature& f : e.features.features) {
    int n = std::snprintf(buf, sizeof buf, "%" PRId64 ",%" PRId64 ",%" PRId64 ",%.3f,%.3f,%.6f,%d,%d,%.6f,%.6f,%.6f,",
                          e.t_ns, e.seq, f.id, f.u, f.v, f.weight, f.times_solved, static_cast<int>(f.sim_label),
                          f.p_w.x(), f.p_w.y(), f.p_w.z());
    // Right pixel of the same observation; both fields empty when it has none (mono, or no stereo match).
    n += f.has_right ? std::snprintf(buf + n, sizeof buf - n, "%.3f,%.3f\n", f.u_r, f.v_r)
                     : std::snprintf(buf + n, sizeof buf - n, ",\n");
    features_ << buf;
    ++totals_.feature_rows;
  }
  check(features_, kFeatures);
}

void RunOutputs::complete(const VioRunResult& run, const RunDescription& what) {
  const bool has_gt = !run.ground_truth.empty();
  eval::Trajectory truth;
  if (has_gt) {
    std::ofstream gt(path(kGroundTruth) + kPartial, std::ios::out | std::ios::trunc);
    check(gt, kGroundTruth);
    gt << "# t[s] x y z qx qy qz qw (ground truth of the source, body in world)\n";
    truth.source = path(kGroundTruth);
    for (const GroundTruthState& g : run.ground_truth) {
      gt << tum_line(g.t_ns, g.p_wb, g.q_wb);
      if (truth.poses.empty() || g.t_ns > truth.poses.back().t_ns) truth.poses.push_back(eval::stamped_pose(g.t_ns, g.p_wb, g.q_wb));
    }
    gt.flush();
    check(gt, kGroundTruth);
    written_.push_back(kGroundTruth);
    if (!estimated_.empty()) {
      estimated_.source = path(kOdometry);
      ate_ = evaluate_ate(truth, estimated_);
    }
  }
  for (auto* f : {&odometry_, &features_, &events_}) {
    f->flush();
    if (!*f) throw std::runtime_error(dir_ + ": writing the outputs failed");
    f->close();
  }
  // trajectory.tum: after the final pose-graph optimisation (the odometry when loop closure is off).
  const LoopRunSummary* loop = run.loop ? &*run.loop : nullptr;
  const eval::Trajectory trajectory = corrected_trajectory(estimated_, loop);
  {
    std::ofstream t(path(kTrajectory) + kPartial, std::ios::out | std::ios::trunc);
    t << "# t[s] x y z qx qy qz qw (every frame after the final pose-graph optimisation; the odometry without loops)\n";
    for (const eval::StampedPose& p : trajectory.poses) t << tum_line(p.t_ns, p.p, p.q);
    t.flush();
    check(t, kTrajectory);
    written_.push_back(kTrajectory);
  }
  std::string loop_section;
  if (loop) {
    const LoopTruthCounts counts = write_loops_csv(path(kLoops) + kPartial, *loop, truth);
    written_.push_back(kLoops);
    loop_section = loop_json(*loop, counts, has_gt);
    if (has_gt && !trajectory.empty()) trajectory_ate_ = evaluate_ate(truth, trajectory);
  }
  summary_ = pipeline::summary_json(run, what, totals_, ate_, totals_.tracking, has_gt);
  if (loop) {  // the loop section goes in front of the pipeline report, the last key
    const std::string tail = "  \"pipeline\": ";
    std::string section = "  \"loop\": " + loop_section + ",\n";
    if (trajectory_ate_.evaluated)
      section += "  \"trajectory_ate_se3_m\": " + num(trajectory_ate_.se3_m) + ",\n  \"trajectory_ate_sim3_m\": " +
                 num(trajectory_ate_.sim3_m) + ",\n";
    summary_.insert(summary_.rfind(tail), section);
  }
  {
    std::ofstream s(path(kSummary) + kPartial, std::ios::out | std::ios::trunc);
    s << summary_ << '\n';
    s.flush();
    check(s, kSummary);
  }
  written_.push_back(kSummary);
  for (const std::string& name : written_) fs::rename(path(name) + kPartial, path(name));
}

std::string summary_json(const VioRunResult& run, const RunDescription& what, const EstimateTotals& totals,
                        const AteResult& ate, int64_t odometry_lines, bool has_ground_truth) {
  std::ostringstream j;
  const double wall = run.report.wall_s, data = run.replay.sensor_s;
  std::vector<double> alternations(totals.alternations.begin(), totals.alternations.end());
  j << "{\n";
  j << "  \"ok\": " << (run.report.ok ? "true" : "false") << ",\n";
  j << "  \"interrupted\": " << (run.interrupted() ? "true" : "false") << ",\n";
  j << "  \"error\": " << json_string(run.report.error) << ",\n";
  j << "  \"mode\": {\"ba\": " << json_string(what.ba_loss) << ", \"cameras\": " << json_string(what.stereo ? "stereo" : "mono")
    << "},\n";
  j << "  \"config\": " << json_string(what.config_path) << ",\n";
  j << "  \"input\": " << json_string(what.input) << ",\n";
  j << "  \"source\": " << json_string(run.source) << ",\n";
  j << "  \"rate\": " << num(what.rate) << ",\n";
  j << "  \"frames_in\": " << run.replay.frames << ",\n";
  j << "  \"frames_tracked\": " << run.frames_tracked << ",\n";
  j << "  \"frames_dropped\": " << run.frames_dropped << ",\n";
  j << "  \"frames_estimated\": " << totals.estimates << ",\n";
  j << "  \"frames_tracking\": " << totals.tracking << ",\n";
  j << "  \"frames_unpaired\": " << run.pairer.unpaired_at_finish + run.pairer.skipped_inside_interval << ",\n";
  j << "  \"frames_restarted_without_imu\": " << run.pairer.restarted_without_imu << ",\n";
  j << "  \"odometry_lines\": " << odometry_lines << ",\n";
  j << "  \"imu_samples\": " << run.replay.imu << ",\n";
  j << "  \"imu_intervals\": " << run.imu.intervals << ",\n";
  j << "  \"imu_intervals_with_gap\": " << run.imu_builder.intervals_with_gap << ",\n";
  j << "  \"ground_truth_states\": " << run.ground_truth.size() << ",\n";
  j << "  \"tracker\": {\"gyro_prediction\": " << (run.gyro_prediction ? "true" : "false")
    << ", \"frames_gyro_predicted\": " << run.frames_gyro_predicted
    << ", \"frames_gyro_unpredicted\": " << run.frames_gyro_unpredicted
    << ", \"features_tracked\": " << run.features_tracked
    << ", \"features_gyro_predicted\": " << run.features_gyro_predicted
    << ", \"features_lost_flow\": " << run.features_lost_flow
    << ", \"features_lost_back\": " << run.features_lost_back << "},\n";
  j << "  \"stage_ms\": {";
  for (std::size_t i = 0; i < run.report.stages.size(); ++i) {
    const StageStats& s = run.report.stages[i];
    j << (i ? ", " : "") << json_string(s.name) << ": {\"mean\": " << num(s.process.mean_ms)
      << ", \"p95\": " << num(s.process.p95_ms) << ", \"processed\": " << s.processed << "}";
  }
  j << "},\n";
  // false at rate 0: each window solve was bounded by max_num_iterations alone (machine-independent).
  j << "  \"solver_time_budget\": " << (run.solver_time_budget ? "true" : "false") << ",\n";
  j << "  \"realtime_threads\": " << run.realtime_threads << ",\n";
  j << "  \"realtime_threads_refused\": " << run.realtime_refused << ",\n";
  j << "  \"ba_solves\": " << totals.ba_ms.size() << ",\n";
  j << "  \"ba_ms_mean\": " << num(mean(totals.ba_ms)) << ",\n";
  j << "  \"ba_ms_p95\": " << num(percentile(totals.ba_ms, 95)) << ",\n";
  j << "  \"ba_ms_max\": " << num(totals.ba_ms.empty() ? 0.0 : *std::max_element(totals.ba_ms.begin(), totals.ba_ms.end()))
    << ",\n";
  j << "  \"alternations_mean\": " << num(mean(alternations)) << ",\n";
  j << "  \"estimator_frame_ms_mean\": " << num(mean(totals.frame_ms)) << ",\n";
  j << "  \"estimator_frame_ms_p95\": " << num(percentile(totals.frame_ms, 95)) << ",\n";
  j << "  \"marginalization_ms_mean\": " << num(mean(totals.marginalization_ms)) << ",\n";
  j << "  \"resets\": " << totals.resets << ",\n";
  j << "  \"standstill_frames\": " << totals.standstill << ",\n";
  j << "  \"estimator_events\": " << totals.events << ",\n";
  j << "  \"wall_s\": " << num(wall) << ",\n";
  j << "  \"data_s\": " << num(data) << ",\n";
  j << "  \"real_time_factor\": " << num(wall > 0 ? data / wall : 0.0) << ",\n";
  j << "  \"peak_rss_mb\": " << num(peak_rss_mb()) << ",\n";
  j << "  \"has_ground_truth\": " << (has_ground_truth ? "true" : "false") << ",\n";
  if (ate.evaluated) {
    j << "  \"ate_se3_m\": " << num(ate.se3_m) << ",\n";
    j << "  \"ate_sim3_m\": " << num(ate.sim3_m) << ",\n";
    j << "  \"ate_matched_poses\": " << ate.matched << ",\n";
  } else if (!ate.error.empty()) {
    j << "  \"ate_error\": " << json_string(ate.error) << ",\n";
  }
  if (run.publisher) {
    const PublisherStats& p = *run.publisher;
    j << "  \"lcm\": {\"url\": " << json_string(p.url) << ", \"imu_poses\": " << p.imu_poses
      << ", \"window_poses\": " << p.window_poses << ", \"feature_sets\": " << p.feature_sets
      << ", \"status\": " << p.status << ", \"stats\": " << p.stats << ", \"failed\": " << p.failed
      << ", \"dropped\": " << run.publish_dropped << ",\n           \"imu_pose_latency_ms\": {\"mean\": "
      << num(p.imu_pose_latency.mean_ms) << ", \"p99\": " << num(p.imu_pose_latency_p99_ms)
      << ", \"max\": " << num(p.imu_pose_latency.max_ms) << "}, \"window_pose_latency_ms\": {\"mean\": "
      << num(p.window_pose_latency.mean_ms) << ", \"p99\": " << num(p.window_pose_latency_p99_ms)
      << ", \"max\": " << num(p.window_pose_latency.max_ms) << "}},\n";
  }
  j << "  \"pipeline\": " << report_to_json(run.report) << "\n";
  j << "}";
  return j.str();
}

}  // namespace dynavins::pipeline
