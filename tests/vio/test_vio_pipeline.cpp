// run_vio on the real EuRoC clip (95 stereo frames, 4.7 s): completes losslessly at full speed, accounts
// for every frame when paced, writes well-formed outputs, seeds the tracker with the gyro (or not, when
// asked), and stops cleanly on a stop request or SIGINT.
#include <algorithm>
#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "io/euroc_dataset.hpp"
#include "io/euroc_source.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/vio/run_outputs.hpp"
#include "pipeline/vio/vio_pipeline.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;
namespace fs = std::filesystem;

namespace {

const std::string kClip = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";
const std::string kConfig = std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml";
constexpr int64_t kClipFrames = 95;

VioRunOptions clip_options(double rate = 0.0, bool gyro_prediction = true) {
  VioRunOptions o;
  o.estimator = EstimatorOptions::load(kConfig);
  o.rate = rate;
  o.show_progress = false;
  o.gyro_prediction = gyro_prediction;
  return o;
}

std::unique_ptr<io::SensorSource> clip() {
  return std::make_unique<io::EurocSource>(std::make_shared<io::EurocDataset>(kClip));
}

std::string fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("dynavins_test_vio_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d.string();
}

std::vector<std::string> data_lines(const std::string& path) {
  std::ifstream f(path);
  REQUIRE(f.good());
  std::vector<std::string> lines;
  for (std::string l; std::getline(f, l);)
    if (!l.empty() && l[0] != '#') lines.push_back(l);
  return lines;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, sep);) out.push_back(x);
  return out;
}

struct RunWithOutputs {
  VioRunResult result;
  std::unique_ptr<RunOutputs> outputs;
};

// Runs the clip into `dir`; `on_estimate(n)` is called on the writer thread after the n-th estimate.
RunWithOutputs run_clip(const std::string& dir, double rate, const StopFlag* stop = nullptr,
                       std::function<void(int)> on_estimate = {}, bool gyro_prediction = true) {
  RunWithOutputs r;
  r.outputs = std::make_unique<RunOutputs>(dir);
  int n = 0;
  VioSinks sinks;
  sinks.estimate = [&](const estimator::WindowEstimate& e) {
    r.outputs->write(e);
    if (on_estimate) on_estimate(++n);
  };
  auto source = clip();
  r.result = run_vio(*source, clip_options(rate, gyro_prediction), sinks, stop);
  RunDescription what{kConfig, "euroc:" + kClip, "dynavins", true, rate};
  if (r.result.report.ok) r.outputs->complete(r.result, what);
  return r;
}

void check_frame_accounting(const VioRunResult& r) {
  CHECK(r.replay.frames == r.frames_tracked + r.frames_dropped);
  CHECK(r.frames_tracked == r.frames_estimated + r.pairer.unpaired_at_finish + r.pairer.skipped_inside_interval +
                                r.pairer.frames_out_of_order);
  for (const auto& q : r.report.queues) CHECK(q.pushed == q.delivered + q.dropped);
  if (r.gyro_prediction) CHECK(r.frames_gyro_predicted + r.frames_gyro_unpredicted == r.frames_tracked);
}

void check_outputs_well_formed(const std::string& dir, const RunOutputs& out) {
  for (const char* name : {"odometry.tum", "features.csv", "estimator_events.csv", "summary.json"}) {
    INFO(name);
    CHECK(fs::exists(fs::path(dir) / name));
    CHECK_FALSE(fs::exists(fs::path(dir) / (std::string(name) + ".partial")));
  }
  const auto odo = data_lines(dir + "/odometry.tum");
  CHECK(static_cast<int64_t>(odo.size()) == out.totals().tracking);
  for (const auto& l : odo) {
    std::istringstream in(l);
    double v[8];
    for (double& x : v) REQUIRE(static_cast<bool>(in >> x));
    CHECK(std::abs(Eigen::Vector4d(v[4], v[5], v[6], v[7]).norm() - 1.0) < 1e-6);
  }
  const auto feats = data_lines(dir + "/features.csv");
  REQUIRE_FALSE(feats.empty());
  CHECK(feats[0] == "t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z,u_r,v_r");
  CHECK(static_cast<int64_t>(feats.size()) - 1 == out.totals().feature_rows);
  // The stereo clip's rows carry the right pixel of the same observation when there is one: inside the
  // 752x480 image, and (cam1 sits 0.11 m right of cam0) mostly further left than the left pixel. Not
  // always: the raw images are not rectified, so far points near the edges can show a negative disparity.
  std::vector<double> disparity;
  for (std::size_t i = 1; i < feats.size(); ++i) {
    CHECK(std::count(feats[i].begin(), feats[i].end(), ',') == 12);
    const auto f = split(feats[i], ',');
    if (f.size() < 13 || f[11].empty()) continue;
    const double u_r = std::stod(f[11]), v_r = std::stod(f[12]);
    CHECK((u_r >= 0 && u_r < 752 && v_r >= 0 && v_r < 480));
    disparity.push_back(std::stod(f[3]) - u_r);
  }
  // A paced run on a loaded machine (ThreadSanitizer, 4x real time) may drop so many frames that the
  // window never fills: no feature rows then, and nothing to check here (rate-0 runs always have them).
  if (out.totals().tracking > 0) {
    REQUIRE(disparity.size() > (feats.size() - 1) / 4);
    std::nth_element(disparity.begin(), disparity.begin() + disparity.size() / 2, disparity.end());
    CHECK(disparity[disparity.size() / 2] > 1.0);
  }
  const auto events = data_lines(dir + "/estimator_events.csv");
  REQUIRE_FALSE(events.empty());
  CHECK(events[0] == "t_ns,seq,event");
  CHECK(static_cast<int64_t>(events.size()) - 1 == out.totals().events);
  std::ifstream s(dir + "/summary.json");
  const std::string json((std::istreambuf_iterator<char>(s)), std::istreambuf_iterator<char>());
  CHECK(json.front() == '{');
  CHECK(json.find("\"frames_estimated\": " + std::to_string(out.totals().estimates) + ",") != std::string::npos);
  CHECK(json.find("\"peak_rss_mb\": ") != std::string::npos);
  CHECK(json.find("\"stage_ms\": {\"replay\"") != std::string::npos);
  CHECK(json == out.summary_json() + "\n");
}

}  // namespace

TEST_CASE("run_vio at full speed processes every frame of the EuRoC clip, losslessly", "[vio]") {
  const std::string dir = fresh_dir("full");
  RunWithOutputs r = run_clip(dir, 0.0);
  const VioRunResult& res = r.result;
  INFO(res.report.error);
  REQUIRE(res.report.ok);
  CHECK_FALSE(res.interrupted());
  CHECK(res.replay.frames == kClipFrames);
  CHECK(res.frames_dropped == 0);
  CHECK(res.frames_tracked == kClipFrames);
  CHECK(res.frames_estimated == kClipFrames);  // IMU spans the clip: every frame gets its interval
  CHECK(res.pairer.emitted_with_imu == kClipFrames - 1);
  CHECK(res.imu.frame_times == kClipFrames);
  CHECK(res.imu.intervals == kClipFrames - 1);
  CHECK(res.imu.imu_samples == res.replay.imu);
  CHECK(r.outputs->totals().estimates == kClipFrames);
  check_frame_accounting(res);
  check_outputs_well_formed(dir, *r.outputs);
  const std::string json = r.outputs->summary_json();
  CHECK(json.find("\"frames_in\": 95,") != std::string::npos);
  CHECK(json.find("\"frames_dropped\": 0,") != std::string::npos);
  CHECK(json.find("\"interrupted\": false,") != std::string::npos);
  // The IMU covers every interval: only the first frame goes without a gyro-predicted rotation.
  CHECK(res.frames_gyro_predicted == kClipFrames - 1);
  CHECK(res.frames_gyro_unpredicted == 1);
  CHECK(res.features_gyro_predicted > 0);
  CHECK(res.features_gyro_predicted > res.features_tracked / 2);  // most KLT converge from the prediction
  CHECK(json.find("\"tracker\": {\"gyro_prediction\": true, \"frames_gyro_predicted\": 94, "
                  "\"frames_gyro_unpredicted\": 1,") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("run_vio with gyro prediction off tracks every frame unseeded", "[vio]") {
  const std::string dir = fresh_dir("nogyro");
  RunWithOutputs r = run_clip(dir, 0.0, nullptr, {}, /*gyro_prediction=*/false);
  const VioRunResult& res = r.result;
  INFO(res.report.error);
  REQUIRE(res.report.ok);
  CHECK(res.frames_tracked == kClipFrames);
  CHECK(res.frames_estimated == kClipFrames);
  CHECK(res.frames_gyro_predicted == 0);
  CHECK(res.frames_gyro_unpredicted == 0);
  CHECK(res.features_gyro_predicted == 0);
  CHECK(res.features_tracked > 0);
  check_frame_accounting(res);
  CHECK(r.outputs->summary_json().find("\"tracker\": {\"gyro_prediction\": false,") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("run_vio paced in real time accounts for every frame, dropped ones included", "[vio]") {
  const std::string dir = fresh_dir("paced");
  RunWithOutputs r = run_clip(dir, 4.0);
  INFO(r.result.report.error);
  REQUIRE(r.result.report.ok);
  CHECK(r.result.replay.frames == kClipFrames);
  check_frame_accounting(r.result);
  CHECK(r.result.frames_estimated >= 1);
  // A frame after a dropped one has no IMU back to the tracker's previous frame: no prediction.
  CHECK(r.result.frames_gyro_unpredicted >= 1 + (r.result.frames_dropped > 0 ? 1 : 0));
  check_outputs_well_formed(dir, *r.outputs);
  fs::remove_all(dir);
}

TEST_CASE("a stop request mid-run drains the queues and marks the run interrupted", "[vio]") {
  const std::string dir = fresh_dir("stop");
  StopFlag stop;
  RunWithOutputs r = run_clip(dir, 0.0, &stop, [&](int n) {
    if (n == 20) stop.request_stop();
  });
  INFO(r.result.report.error);
  REQUIRE(r.result.report.ok);
  CHECK(r.result.interrupted());
  CHECK(r.result.frames_estimated >= 20);
  CHECK(r.result.replay.frames < kClipFrames);
  check_frame_accounting(r.result);
  check_outputs_well_formed(dir, *r.outputs);
  CHECK(r.outputs->summary_json().find("\"interrupted\": true,") != std::string::npos);
  fs::remove_all(dir);
}

TEST_CASE("SIGINT mid-run stops the replay cleanly", "[vio]") {
  const std::string dir = fresh_dir("sigint");
  install_interrupt_handler();
  clear_interrupt();
  RunWithOutputs r = run_clip(dir, 0.0, nullptr, [](int n) {
    if (n == 10) std::raise(SIGINT);
  });
  clear_interrupt();
  INFO(r.result.report.error);
  REQUIRE(r.result.report.ok);
  CHECK(r.result.interrupted());
  CHECK(r.result.replay.frames < kClipFrames);
  check_frame_accounting(r.result);
  check_outputs_well_formed(dir, *r.outputs);
  fs::remove_all(dir);
}

TEST_CASE("odometry has one line per frame once the estimator tracks", "[vio]") {
  const std::string dir = fresh_dir("odometry");
  int64_t first_tracking = -1, n = 0, tracking_after = 0;
  RunOutputs outputs(dir);
  VioSinks sinks;
  sinks.estimate = [&](const estimator::WindowEstimate& e) {
    outputs.write(e);
    const bool t = e.status == estimator::EstimatorStatus::Tracking;
    if (t && first_tracking < 0) first_tracking = n;
    if (first_tracking >= 0 && t) ++tracking_after;
    ++n;
  };
  auto source = clip();
  const VioRunResult r = run_vio(*source, clip_options(), sinks);
  REQUIRE(r.report.ok);
  outputs.complete(r, RunDescription{kConfig, kClip, "dynavins", true, 0.0});
  REQUIRE(first_tracking >= 0);
  CHECK(first_tracking < 30);  // a standing start initialises within the first 1.5 s
  CHECK(tracking_after == n - first_tracking);
  CHECK(static_cast<int64_t>(data_lines(dir + "/odometry.tum").size()) == n - first_tracking);
  fs::remove_all(dir);
}
