// bench_track_accuracy: how close the tracker's pixels are to the truth, on one simulated scenario,
// tracker alone (deterministic, seconds). Three numbers a tracker change should be judged by before
// any ATE, which one noise draw moves by up to 4x at night (README, "Street scenes"):
//   - track error by track length: each static track's point is fixed at its first observation (true
//     depth under the pixel) and projected with the true pose into every later frame;
//   - fit: the best 3-D point of each static track (5+ observations, true poses) and its residuals,
//     i.e. how well a track's observations agree with each other, whatever its first pixel;
//   - stereo: each right observation against the true point under the same frame's left pixel;
//   - near moving objects: the track error by how close the static track is to a
//     moving object's pixels, and its mean component along the point's true image motion since the
//     first observation (negative: the track lags, held back by the object's edge; issue 23's
//     leading truck, where such tracks make the estimated speed short).
// The gyro's rotation prediction is the true rotation (the pipeline uses the gyro's).
//   bench_track_accuracy --scenario street_crowd_night --seed 25 --duration 12 [--mono] [--set k=v]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bench/true_depth.hpp"
#include "sim/scenario/scenario.hpp"
#include "sim/scenario/scenario_config.hpp"
#include "sim/scenario/scenario_spec.hpp"
#include "stages/tracker/stereo_tracker.hpp"

using namespace dynavins;

namespace {

constexpr double kFocal = 460.0;  // errors in pixels of VINS' virtual camera, as everywhere in the benches

struct Observation {
  Eigen::Isometry3d T_wc;
  Eigen::Vector2d xy;
};

/// Chebyshev distance [px] from `px` to the nearest moving-object pixel of `labels`, or reach + 1.
int moving_distance(const cv::Mat& labels, const Eigen::Vector2d& px, int reach) {
  const int cx = static_cast<int>(px.x()), cy = static_cast<int>(px.y());
  int best = reach + 1;
  for (int y = std::max(0, cy - reach); y <= std::min(labels.rows - 1, cy + reach); ++y) {
    const uchar* row = labels.ptr<uchar>(y);
    for (int x = std::max(0, cx - reach); x <= std::min(labels.cols - 1, cx + reach); ++x)
      if (row[x] > 0) best = std::min(best, std::max(std::abs(x - cx), std::abs(y - cy)));
  }
  return best;
}

/// Static observations in one band of distance to moving pixels.
struct NearMovingBand {
  explicit NearMovingBand(const char* n) : name(n) {}
  const char* name;
  std::vector<double> err;  ///< [px] against the truth
  double lag_sum = 0, lag_good_sum = 0;
  long lag_good_n = 0;
  void add(double e, double lag) {
    err.push_back(e);
    lag_sum += lag;
    if (e < 2.0) lag_good_sum += lag, ++lag_good_n;
  }
};

void print_stats(const char* name, std::vector<double> v) {
  if (v.empty()) {
    std::printf("%-22s n      0\n", name);
    return;
  }
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))]; };
  std::printf("%-22s n %6zu  p50 %.3f  p90 %.3f px\n", name, v.size(), at(0.5), at(0.9));
}

/// Residuals [px] of the least-squares point of the rays (sum of squared distances to each ray).
void fit_residuals(const std::vector<Observation>& obs, std::vector<double>* out) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Observation& o : obs) {
    const Eigen::Vector3d d = (o.T_wc.linear() * o.xy.homogeneous()).normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - d * d.transpose();
    A += P;
    b += P * o.T_wc.translation();
  }
  const Eigen::Vector3d X = A.ldlt().solve(b);
  for (const Observation& o : obs) {
    const Eigen::Vector3d p = o.T_wc.inverse() * X;
    if (p.z() > 0) out->push_back(kFocal * (p.head<2>() / p.z() - o.xy).norm());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Tracker accuracy against the simulator's truth on one scenario (static features only)"};
  std::string scenario = "street_crowd_night";
  std::optional<uint64_t> seed;
  std::optional<double> duration;
  bool mono = false;
  std::string rig;
  std::vector<std::string> sets;
  app.add_option("--scenario", scenario, "Name in bench/scenarios or a file")->capture_default_str();
  app.add_option("--seed", seed, "Noise seed (default: the scenario's)");
  app.add_option("--duration", duration, "Seconds to simulate (default: the scenario's)");
  app.add_flag("--mono", mono, "Left image only");
  app.add_option("--rig", rig, "Override the scenario's stereo rig (as dynavins sim --rig): euroc or viode");
  app.add_option(
      "--set", sets,
      "Override an option by its config key, --set key=value (repeatable; only the tracker's keys act here)");
  CLI11_PARSE(app, argc, argv);

  std::string path = scenario;
  if (!std::filesystem::is_regular_file(path))
    path = std::string(DYNAVINS_SOURCE_DIR) + "/bench/scenarios/" + scenario + ".yaml";
  std::shared_ptr<const sim::Scenario> sc;
  tracker::TrackerOptions options;
  EstimatorOptions est;
  try {
    sim::ScenarioSpec spec = sim::load_scenario(path);
    if (!seed) seed = spec.seed;
    if (!rig.empty()) spec.rig = rig;
    sc = sim::build_scenario(spec, seed, duration);
    est = sim::scenario_estimator_options(*sc);
    for (const std::string& s : sets) {
      const auto [key, value] = EstimatorOptions::parse_override(s);
      est.apply(key, value);
    }
    options = tracker::TrackerOptions::from(est);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  tracker::StereoTracker tracker(options, est.cameras.at(0), mono ? nullptr : est.cameras.at(1));
  sim::ScenarioSource src(sc);

  const int kBins = 5;
  const int edges[kBins + 1] = {2, 3, 5, 9, 17, 1 << 30};
  std::vector<double> by_length[kBins], stereo;
  std::map<int64_t, Eigen::Vector3d> points;        // static tracks' true points (first observation)
  std::map<int64_t, std::vector<Observation>> seen;  // every static observation, for the fit
  std::map<int64_t, int> moving_seen;                // observations on moving objects, per track
  std::map<int64_t, Eigen::Vector2d> first_px;       // static tracks' first pixel (460 px focal)
  std::map<int64_t, bool> was_near;                  // static tracks that came within 10 px of a moving object
  NearMovingBand near[5] = {NearMovingBand("within 10 px"), NearMovingBand("11-20 px"), NearMovingBand("21-40 px"),
                            NearMovingBand("farther, once within 10"), NearMovingBand("farther, never within 10")};
  std::optional<Eigen::Isometry3d> prev_T_wc;
  long frames = 0, features = 0, with_right = 0;
  SensorEvent e;
  while (src.next(e)) {
    auto* f = std::get_if<StereoFrame>(&e);
    if (!f) continue;
    StereoFrame frame = *f;
    if (mono) frame.right = cv::Mat();
    const double t = static_cast<double>(f->t_ns - sc->epoch_ns) * 1e-9;
    const Eigen::Isometry3d T_wb = sc->body->pose(t);
    const Eigen::Isometry3d T_wc = T_wb * sc->rig.T_body_cam0, T_wc1 = T_wb * sc->rig.T_body_cam1;
    std::optional<Eigen::Matrix3d> R_prev_curr;
    if (prev_T_wc) R_prev_curr = prev_T_wc->linear().transpose() * T_wc.linear();
    prev_T_wc = T_wc;
    const TrackedFrame out = tracker.process(frame, R_prev_curr);
    const cv::Mat& depth = src.last_left().depth;
    ++frames;
    features += static_cast<long>(out.features.size());
    with_right += out.stats.stereo;
    for (const TrackedFeature& tf : out.features) {
      if (tf.sim_label > 0) ++moving_seen[tf.id];
      if (tf.sim_label != 0) continue;
      seen[tf.id].push_back({T_wc, tf.xy});
      const std::optional<double> z = bench::true_depth(depth, tf.px);
      const auto point = [&] { return T_wc * (*z * tf.xy.homogeneous()); };
      if (tf.has_right && z) {
        const Eigen::Vector3d p1 = T_wc1.inverse() * point();
        stereo.push_back(kFocal * (p1.head<2>() / p1.z() - tf.xy_right).norm());
      }
      auto it = points.find(tf.id);
      if (it == points.end()) {
        if (tf.track_length == 1 && z) points.emplace(tf.id, point()), first_px.emplace(tf.id, kFocal * tf.xy);
        continue;
      }
      const Eigen::Vector3d p = T_wc.inverse() * it->second;
      if (p.z() <= 0) continue;
      {
        const int d = moving_distance(src.last_left().labels, tf.px, 40);
        if (d <= 10) was_near[tf.id] = true;
        const int band = d <= 10 ? 0 : d <= 20 ? 1 : d <= 40 ? 2 : was_near[tf.id] ? 3 : 4;
        const Eigen::Vector2d truth = kFocal * (p.head<2>() / p.z()), error = kFocal * tf.xy - truth;
        const Eigen::Vector2d motion = truth - first_px.at(tf.id);
        near[band].add(error.norm(), motion.norm() > 1.0 ? error.dot(motion.normalized()) : 0.0);
      }
      for (int k = 0; k < kBins; ++k)
        if (tf.track_length >= edges[k] && tf.track_length < edges[k + 1])
          by_length[k].push_back(kFocal * (p.head<2>() / p.z() - tf.xy).norm());
    }
  }

  std::printf("%s, seed %llu, %s: static features, error against the truth\n", scenario.c_str(),
              static_cast<unsigned long long>(*seed), mono ? "mono" : "stereo");
  std::vector<double> all;
  for (int k = 0; k < kBins; ++k) {
    all.insert(all.end(), by_length[k].begin(), by_length[k].end());
    const std::string name = k + 1 < kBins ? "track length " + std::to_string(edges[k]) + "-" + std::to_string(edges[k + 1] - 1)
                                           : "track length " + std::to_string(edges[k]) + "+";
    print_stats(name.c_str(), by_length[k]);
  }
  print_stats("track, all lengths", all);
  // How long tracks live (a track that ends early is replaced by a fresh corner). On moving objects
  // too: a tracker change that keeps tracks alive longer keeps a truck's as well, which the estimator
  // then has to reject (README, "Street scenes": the averaged first patch on `high`).
  const auto lifetimes = [](const std::vector<double>& lengths) {
    if (lengths.empty()) return std::string("n      0");
    std::vector<double> v = lengths;
    std::sort(v.begin(), v.end());
    char buf[128];
    std::snprintf(buf, sizeof buf, "n %6zu  mean length %.1f, median %.0f frames", v.size(),
                  std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()), v[v.size() / 2]);
    return std::string(buf);
  };
  std::vector<double> static_lengths, moving_lengths;
  for (const auto& [id, obs] : seen) static_lengths.push_back(static_cast<double>(obs.size()));
  for (const auto& [id, n] : moving_seen) moving_lengths.push_back(n);
  std::printf("static tracks          %s; %.1f features per frame, %.0f %% with a right match\n",
              lifetimes(static_lengths).c_str(), static_cast<double>(features) / static_cast<double>(std::max(1L, frames)),
              100.0 * static_cast<double>(with_right) / static_cast<double>(std::max(1L, features)));
  std::printf("tracks on moving objs  %s\n", lifetimes(moving_lengths).c_str());
  std::vector<double> fit;
  for (const auto& [id, obs] : seen)
    if (obs.size() >= 5) fit_residuals(obs, &fit);
  print_stats("fit (5+ observations)", fit);
  if (!mono) {
    print_stats("stereo", stereo);
    // Wrong matches, which the flow-back check lets through: each one is a depth the estimator trusts.
    const auto share = [&](double px) {
      return 100.0 *
             static_cast<double>(std::count_if(stereo.begin(), stereo.end(), [px](double e) { return e > px; })) /
             static_cast<double>(std::max<std::size_t>(1, stereo.size()));
    };
    std::printf("stereo outliers        > 1 px %.2f %%, > 3 px %.2f %%\n", share(1.0), share(3.0));
  }
  {
    std::printf(
        "static observations by distance to moving pixels: error, > 2 px, mean error along the true image motion\n");
    std::printf("since the first observation (negative: lagging), of all and of those within 2 px\n");
    for (NearMovingBand& b : near) {
      if (b.err.empty()) continue;
      const double n = static_cast<double>(b.err.size());
      const double drifted = static_cast<double>(std::count_if(b.err.begin(), b.err.end(), [](double e) { return e > 2.0; }));
      const double lag = b.lag_sum / n, lag_good = b.lag_good_sum / static_cast<double>(std::max(1L, b.lag_good_n));
      std::sort(b.err.begin(), b.err.end());
      std::printf("  %-24s n %6zu  p50 %.3f  p90 %.3f px, > 2 px %5.1f %%, along the motion %+.3f px (within 2 px: %+.4f)\n",
                  b.name, b.err.size(), b.err[b.err.size() / 2], b.err[b.err.size() * 9 / 10], 100.0 * drifted / n, lag, lag_good);
    }
  }
  return 0;
}
