// bench_estimator: one scenario, huber and dynavins side by side through the shipped chain run on one
// thread (run_vio_sequential: the stages of `dynavins run`, deterministic): ATE, feature scoring, BA ms, and
// how far each static track strays from its true point.
//   bench_estimator --scenario high [--duration S] [--mono] [--ba huber,dynavins]
#include <filesystem>
#include <sstream>
#include <iostream>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bench/true_depth.hpp"
#include "eval/evaluation.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/vio/estimate_recorder.hpp"
#include "pipeline/vio/vio_pipeline.hpp"
#include "sim/scenario/scenario.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"

using namespace dynavins;

namespace {
/// How far each static track strays from its true 3-D point: the point is fixed at the track's first
/// observation (true depth under the pixel) and projected with the true pose into every later frame.
class TrackTruth {
 public:
  TrackTruth(const sim::ScenarioSource& src, const sim::Scenario& sc) : src_(src), sc_(sc) {}
  void operator()(const TrackedFrame& f) {
    const double t = (f.t_ns - sc_.epoch_ns) * 1e-9;
    const Eigen::Isometry3d T_wc = sc_.body->pose(t) * sc_.rig.T_body_cam0;
    const cv::Mat& depth = src_.last_left().depth;
    for (const TrackedFeature& tf : f.features) {
      if (tf.sim_label != 0) continue;
      auto it = points_.find(tf.id);
      if (it == points_.end()) {
        // True depth under the sub-pixel corner; corners on a depth edge are left unscored.
        const std::optional<double> depth_m = bench::true_depth(depth, tf.px);
        if (!depth_m) continue;
        const double z = *depth_m;
        points_[tf.id] = T_wc * Eigen::Vector3d(tf.xy.x() * z, tf.xy.y() * z, z);
        max_err_[tf.id] = 0;
        continue;
      }
      const Eigen::Vector3d p_c = T_wc.inverse() * it->second;
      if (p_c.z() <= 0) continue;
      const double e = 460.0 * (p_c.head<2>() / p_c.z() - tf.xy).norm();
      max_err_[tf.id] = std::max(max_err_[tf.id], e);
    }
  }
  /// Largest error of the track so far [px at 460], or -1 when unknown.
  double max_error(int64_t id) const {
    auto it = max_err_.find(id);
    return it == max_err_.end() ? -1 : it->second;
  }

 private:
  const sim::ScenarioSource& src_;
  const sim::Scenario& sc_;
  std::map<int64_t, Eigen::Vector3d> points_;
  std::map<int64_t, double> max_err_;
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Huber vs DynaVINS on one simulated scenario (sequential, deterministic)"};
  std::string scenario = "high", modes = "huber,dynavins", level = "warn";
  std::optional<double> duration;
  bool mono = false;
  std::string out_dir;
  std::vector<std::string> sets;
  app.add_option("--scenario", scenario, "Name in bench/scenarios or a file")->capture_default_str();
  app.add_option("--duration", duration, "Seconds to simulate (default: the scenario's)");
  app.add_option("--ba", modes, "Comma-separated BA losses")->capture_default_str();
  app.add_flag("--mono", mono, "Mono-inertial (cam0 only)");
  app.add_option("--log-level", level)->capture_default_str();
  app.add_option("--out", out_dir, "Write <ba>.tum and groundtruth.tum here");
  app.add_option("--set", sets, "Override an estimator / tracker option: --set key=value (repeatable)");
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(level));

  // Checked before the scenario is built (seconds), on the defaults: the same keys and ranges.
  std::vector<std::pair<std::string, std::string>> overrides;
  try {
    EstimatorOptions check;
    for (const std::string& s : sets) {
      overrides.push_back(EstimatorOptions::parse_override(s));
      check.apply(overrides.back().first, overrides.back().second);
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }

  std::string path = scenario;
  if (!std::filesystem::is_regular_file(path)) path = std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/" + scenario + ".yaml";
  const auto sc = sim::build_scenario(sim::load_scenario(path), std::nullopt, duration);
  // Rate 0: iteration-bound solves (max_num_iterations only), so the answer does not depend on machine load.
  pipeline::VioRunOptions opt;
  opt.estimator = sim::scenario_estimator_options(*sc);
  for (const auto& [key, value] : overrides) opt.estimator.apply(key, value);
  opt.show_progress = false;

  std::stringstream ss(modes);
  std::string m;
  while (std::getline(ss, m, ',')) {
    opt.mode.loss = estimator::parse_ba_loss(m);
    opt.mode.stereo = !mono;
    sim::ScenarioSource src(sc);
    TrackTruth truth(src, *sc);
    pipeline::EstimateRecorder r;
    pipeline::VioSinks sinks;
    sinks.estimate = [&r](const estimator::WindowEstimate& e) { r.record(e); };
    // Sequential: the tracker sees each frame while the source's last rendered frame (its depth) is it.
    sinks.tracked = [&truth](const TrackedFrame& f) { truth(f); };
    const pipeline::VioRunResult run = pipeline::run_vio_sequential(src, opt, sinks);
    if (!run.report.ok) {
      spdlog::error("{}: {} failed: {}", m, run.report.failed_thread, run.report.error);
      return 1;
    }
    const eval::Trajectory ground_truth = pipeline::ground_truth_trajectory(run.ground_truth);
    if (!out_dir.empty()) {
      std::filesystem::create_directories(out_dir);
      eval::write_tum(out_dir + "/" + m + ".tum", r.estimate);
      eval::write_tum(out_dir + "/groundtruth.tum", ground_truth);
    }
    double ate = -1;
    try {
      ate = eval::evaluate(ground_truth, r.estimate).ate.rmse;
    } catch (const std::exception& e) {
      spdlog::warn("{}: no ATE: {}", m, e.what());
    }
    std::vector<double> ba = r.ba_ms;
    std::sort(ba.begin(), ba.end());
    double mean = 0;
    for (double v : ba) mean += v;
    mean = ba.empty() ? 0 : mean / ba.size();
    const double p95 = ba.empty() ? 0 : ba[static_cast<size_t>(0.95 * (ba.size() - 1))];
    const auto sw = eval::score_weights(r.features);
    std::printf("%-9s %s %s: ATE %.4f m | frames %d tracking %d resets %d | BA ms mean %.2f p95 %.2f | "
                "moving %d rejected %.1f%% | static %d kept %.1f%%\n",
                m.c_str(), scenario.c_str(), mono ? "mono" : "stereo", ate, r.frames, r.tracking_frames, r.resets,
                mean, p95, sw.moving, 100 * sw.moving_rejected, sw.stationary, 100 * sw.static_kept);
    int low_by_n[4] = {0, 0, 0, 0};  // static features ending under 0.5, by solves: 1, 2-3, 4-9, 10+
    for (const auto& [id, f] : r.features) {
      if (f.sim_label != 0 || f.weight >= 0.5f || f.times_solved == 0) continue;
      ++low_by_n[f.times_solved == 1 ? 0 : f.times_solved < 4 ? 1 : f.times_solved < 10 ? 2 : 3];
    }
    int kept_good = 0, good = 0, drifted = 0, drifted_low = 0;  // static tracks true to 2 px, and the rest
    for (const auto& [id, f] : r.features) {
      if (f.sim_label != 0 || f.times_solved == 0) continue;
      const double e = truth.max_error(id);
      if (e < 0) continue;
      if (e <= 2.0) {
        ++good;
        kept_good += f.weight > 0.5f;
      } else {
        ++drifted;
        drifted_low += f.weight < 0.5f;
      }
    }
    std::vector<double> e_low, e_high, e_mid, e_top;  // e_mid / e_top split e_high at weight 0.9
    for (const auto& [id, f] : r.features) {
      if (f.sim_label != 0 || f.times_solved == 0 || truth.max_error(id) < 0) continue;
      (f.weight < 0.5f ? e_low : e_high).push_back(truth.max_error(id));
      if (f.weight >= 0.5f) (f.weight < 0.9f ? e_mid : e_top).push_back(truth.max_error(id));
    }
    auto q = [](std::vector<double> v, double p) {
      if (v.empty()) return -1.0;
      std::sort(v.begin(), v.end());
      return v[static_cast<size_t>(p * (v.size() - 1))];
    };
    std::printf("          true track error [px] of static features, weight < 0.5: p10 %.1f p50 %.1f p90 %.1f (n=%zu); "
                ">= 0.5: p10 %.1f p50 %.1f p90 %.1f (n=%zu)\n",
                q(e_low, 0.1), q(e_low, 0.5), q(e_low, 0.9), e_low.size(), q(e_high, 0.1), q(e_high, 0.5), q(e_high, 0.9),
                e_high.size());
    // The kept tracks the eq. (7) kernel still down-weights (w² < 0.81) against the ones it barely touches.
    std::printf("          kept static, weight 0.5-0.9: p50 %.1f p90 %.1f (n=%zu); >= 0.9: p50 %.1f p90 %.1f (n=%zu)\n",
                q(e_mid, 0.5), q(e_mid, 0.9), e_mid.size(), q(e_top, 0.5), q(e_top, 0.9), e_top.size());
    std::printf("          static tracks true within 2 px: %d, kept %.1f%% | drifted > 2 px: %d, rejected %.1f%%\n", good,
                good ? 100.0 * kept_good / good : 0.0, drifted, drifted ? 100.0 * drifted_low / drifted : 0.0);
    std::printf("          static under 0.5 by solves: 1: %d, 2-3: %d, 4-9: %d, 10+: %d\n", low_by_n[0], low_by_n[1],
                low_by_n[2], low_by_n[3]);
    std::fflush(stdout);
  }
  return 0;
}
