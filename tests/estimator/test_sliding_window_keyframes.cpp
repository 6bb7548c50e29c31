// SlidingWindowEstimator's keyframes for the loop closer (WindowEstimate::finished_keyframes and
// flush_keyframes()), on the real EuRoC clip driven by hand: EurocDataset -> StereoTracker ->
// ImuIntervalBuilder -> estimator, one frame at a time (deterministic). Checks that every keyframe goes out
// once, in time order, only frames the window kept; its pose is the window's (close to the frame's own
// estimate), its points and weights are sane, and its image is the tracker's left image, not a copy, held
// only while the frame is in the window.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "io/euroc_dataset.hpp"
#include "stages/common/estimator_options.hpp"
#include "stages/estimator/sliding_window_estimator.hpp"
#include "stages/imu/imu_interval_builder.hpp"
#include "stages/tracker/stereo_tracker.hpp"
#include "stages/tracker/tracker_options.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

const std::string kClip = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";
const std::string kConfig =
    std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml";

struct ClipRun {
  std::vector<WindowEstimate> estimates;   // finished_keyframes moved out into `finished`
  std::vector<Keyframe> finished;          // from the estimates, in arrival order
  std::vector<int> finished_per_estimate;  // how many each estimate carried
  std::vector<Keyframe> flushed;           // flush_keyframes() after the last frame
  std::vector<Keyframe> flushed_again;     // a second flush: must be empty
  std::map<int64_t, cv::Mat> left;         // the loaded left image of every frame, by time
  int max_images_held = 0;                 // most left images the estimator held at once (beyond this test's)
  EstimatorOptions options;
};

/// Left images referenced by someone besides `run.left` (the estimator's window, the keyframes kept here).
int images_held_elsewhere(const ClipRun& run) {
  int n = 0;
  for (const auto& [t, m] : run.left) n += (m.u != nullptr && m.u->refcount > 1) ? 1 : 0;
  return n;
}

/// With `drop_imu_at` >= 0, that frame comes without its IMU interval (an outage: the estimator resets).
ClipRun run_clip(int drop_imu_at = -1) {
  ClipRun run;
  run.options = EstimatorOptions::load(kConfig);
  run.options.max_solver_time = 1e9;  // iteration budget only: the run must not depend on the machine
  const io::EurocDataset data(kClip);
  tracker::StereoTracker tracker(tracker::TrackerOptions::from(run.options), run.options.cameras.at(0), run.options.cameras.at(1));
  SlidingWindowEstimator est(run.options, EstimatorMode{});

  // Every interval first (the whole clip's IMU is at hand), keyed by its start frame.
  imu::ImuIntervalBuilderOptions bo;
  bo.noise.acc_n = run.options.acc_n;
  bo.noise.gyr_n = run.options.gyr_n;
  bo.noise.acc_w = run.options.acc_w;
  bo.noise.gyr_w = run.options.gyr_w;
  imu::ImuIntervalBuilder builder(bo);
  std::map<int64_t, PreintegratedInterval> intervals;
  std::size_t next_imu = 0;
  const auto& imu = data.imu();
  for (const io::EurocFrame& f : data.frames()) {
    while (next_imu < imu.size() && imu[next_imu].t_ns <= f.t_ns)
      for (auto& iv : builder.add_imu(imu[next_imu++])) intervals[iv.t_begin_ns] = std::move(iv);
    for (auto& iv : builder.add_frame(f.t_ns)) intervals[iv.t_begin_ns] = std::move(iv);
  }
  while (next_imu < imu.size())
    for (auto& iv : builder.add_imu(imu[next_imu++])) intervals[iv.t_begin_ns] = std::move(iv);

  const int64_t first_imu_ns = imu.front().t_ns;
  int64_t prev_t = -1;
  for (std::size_t i = 0; i < data.frames().size(); ++i) {
    if (data.frames()[i].t_ns < first_imu_ns) continue;  // no IMU before it: the builder dropped it
    StereoFrame sf = data.load(i);
    sf.seq = static_cast<int64_t>(i);
    run.left[sf.t_ns] = sf.left;
    TrackedFrame tf = tracker.process(sf);
    sf = StereoFrame{};  // the images now live in run.left and wherever the tracked frame put them
    const PreintegratedInterval* iv = nullptr;
    if (prev_t >= 0 && static_cast<int>(run.estimates.size()) != drop_imu_at) {
      auto it = intervals.find(prev_t);
      if (it == intervals.end()) break;  // the clip's IMU ends before this frame
      iv = &it->second;
    }
    WindowEstimate e = est.process(tf, iv);
    tf = TrackedFrame{};
    prev_t = e.t_ns;
    run.finished_per_estimate.push_back(static_cast<int>(e.finished_keyframes.size()));
    for (Keyframe& kf : e.finished_keyframes) run.finished.push_back(std::move(kf));
    e.finished_keyframes.clear();
    // Keyframes handed out hold their images too; count only the estimator's.
    std::vector<cv::Mat> kept_images;
    for (Keyframe& kf : run.finished) kept_images.push_back(std::exchange(kf.image, cv::Mat()));
    run.max_images_held = std::max(run.max_images_held, images_held_elsewhere(run));
    for (std::size_t k = 0; k < kept_images.size(); ++k) run.finished[k].image = kept_images[k];
    run.estimates.push_back(std::move(e));
  }
  run.flushed = est.flush_keyframes();
  run.flushed_again = est.flush_keyframes();
  return run;
}

const ClipRun& clip_run() {
  static const ClipRun kRun = run_clip();
  return kRun;
}

}  // namespace

TEST_CASE("keyframes leave the window once each, in time order, only frames the window kept",
          "[estimator][keyframes]") {
  const ClipRun& run = clip_run();
  int tracking = 0;
  for (const auto& e : run.estimates) tracking += e.status == EstimatorStatus::Tracking ? 1 : 0;
  REQUIRE(tracking > 50);

  std::vector<Keyframe> all = run.finished;
  all.insert(all.end(), run.flushed.begin(), run.flushed.end());
  CHECK(run.flushed_again.empty());
  REQUIRE(!run.flushed.empty());
  CHECK(static_cast<int>(run.flushed.size()) <= run.options.window_size);
  for (std::size_t k = 1; k < all.size(); ++k) CHECK(all[k].t_ns > all[k - 1].t_ns);

  // Frames the window dropped as the second newest (no keyframe) while tracking must never come out; every
  // frame it kept (the next estimate says keyframe) must, by the end.
  std::set<int64_t> dropped, kept, frame_times;
  for (std::size_t i = 0; i < run.estimates.size(); ++i) {
    frame_times.insert(run.estimates[i].t_ns);
    if (i + 1 < run.estimates.size() && run.estimates[i].status == EstimatorStatus::Tracking &&
        run.estimates[i + 1].status == EstimatorStatus::Tracking) {
      (run.estimates[i + 1].keyframe ? kept : dropped).insert(run.estimates[i].t_ns);
    }
  }
  std::set<int64_t> out_times;
  for (const Keyframe& kf : all) {
    INFO("keyframe at t = " << kf.t_ns);
    CHECK(frame_times.count(kf.t_ns) == 1);
    CHECK(dropped.count(kf.t_ns) == 0);
    out_times.insert(kf.t_ns);
  }
  for (int64_t t : kept) CHECK(out_times.count(t) == 1);
  // Finished ones come only with a Tracking estimate that marginalised the oldest keyframe (no resets here).
  for (std::size_t i = 0; i < run.estimates.size(); ++i) {
    const WindowEstimate& e = run.estimates[i];
    CHECK(run.finished_per_estimate[i] == (e.status == EstimatorStatus::Tracking && e.keyframe ? 1 : 0));
  }
  WARN("estimates " << run.estimates.size() << ", tracking " << tracking << ", kept " << kept.size() << ", dropped "
                    << dropped.size() << ", finished " << run.finished.size() << ", flushed " << run.flushed.size());
}

TEST_CASE("a keyframe carries its window pose, the extrinsic, weighted points and the left image",
          "[estimator][keyframes]") {
  const ClipRun& run = clip_run();
  std::map<int64_t, const WindowEstimate*> by_time;
  for (const auto& e : run.estimates) by_time[e.t_ns] = &e;
  std::vector<Keyframe> all = run.finished;
  all.insert(all.end(), run.flushed.begin(), run.flushed.end());
  REQUIRE(!all.empty());

  const Eigen::Isometry3d& T_bc = run.options.body_T_cam.at(0);
  double max_dp = 0, max_dq_deg = 0, min_share_p_w = 1;
  for (const Keyframe& kf : all) {
    INFO("keyframe at t = " << kf.t_ns);
    // The window refines a frame's pose after its own estimate; on this slow clip only by millimetres.
    const WindowEstimate& own = *by_time.at(kf.t_ns);
    CHECK(kf.seq == own.seq);
    if (own.status == EstimatorStatus::Tracking) {
      max_dp = std::max(max_dp, (kf.p_wb - own.state.p_wb).norm());
      max_dq_deg = std::max(max_dq_deg, Eigen::AngleAxisd(own.state.q_wb.conjugate() * kf.q_wb).angle() * 180 / M_PI);
    }
    CHECK(std::abs(kf.q_wb.norm() - 1.0) < 1e-9);
    CHECK((kf.p_bc - T_bc.translation()).norm() < 1e-12);
    CHECK((kf.q_bc.toRotationMatrix() - T_bc.linear()).norm() < 1e-9);

    REQUIRE(!kf.image.empty());
    CHECK(kf.image.data == run.left.at(kf.t_ns).data);  // the loaded image itself: a shallow copy

    REQUIRE(kf.points.size() >= 20);
    std::set<int64_t> ids;
    int with_p_w = 0;
    for (const KeyframePoint& p : kf.points) {
      CHECK(p.id >= 0);
      ids.insert(p.id);
      CHECK(p.weight >= 0.f);
      CHECK(p.weight <= 1.f);
      CHECK(p.px.x() >= 0);
      CHECK(p.px.x() < kf.image.cols);
      CHECK(p.px.y() >= 0);
      CHECK(p.px.y() < kf.image.rows);
      // The pixel and the z = 1 point are one observation: the camera model maps one onto the other.
      const Eigen::Vector3d b = run.options.cameras.at(0)->lift(p.px);
      CHECK((b.head<2>() / b.z() - p.xy).norm() < 1e-9);
      if (!p.has_p_w) continue;
      ++with_p_w;
      // The point lies in front of the keyframe's camera, near its ray (the window's own depth).
      const Eigen::Matrix3d R_wc = kf.q_wb.toRotationMatrix() * kf.q_bc.toRotationMatrix();
      const Eigen::Vector3d p_wc = kf.p_wb + kf.q_wb * kf.p_bc;
      const Eigen::Vector3d p_c = R_wc.transpose() * (p.p_w - p_wc);
      CHECK(p_c.z() > 0.1);
    }
    CHECK(ids.size() == kf.points.size());
    min_share_p_w = std::min(min_share_p_w, static_cast<double>(with_p_w) / kf.points.size());
  }
  CHECK(max_dp < 0.05);
  CHECK(max_dq_deg < 1.0);
  CHECK(min_share_p_w > 0.5);
  WARN("keyframes " << all.size() << ": pose moved after its own estimate by at most " << max_dp * 100 << " cm, "
                    << max_dq_deg << " deg; share of points with p_w at least " << min_share_p_w);
}

TEST_CASE("the estimator holds left images only while their frames are in the window", "[estimator][keyframes]") {
  const ClipRun& run = clip_run();
  // window_size + 1 slots, plus the one being tracked and estimated
  CHECK(run.max_images_held <= run.options.window_size + 2);
  CHECK(run.max_images_held >= run.options.window_size);
  WARN("left images held by the estimator at most: " << run.max_images_held);
}

TEST_CASE("a reset found before the solve hands out the window's keyframes with the Reset estimate",
          "[estimator][keyframes]") {
  const ClipRun run = run_clip(60);
  REQUIRE(run.estimates.at(59).status == EstimatorStatus::Tracking);
  REQUIRE(run.estimates.at(60).status == EstimatorStatus::Reset);
  // The window's keyframes (all but its newest frame, estimate 59) with the poses of the last Tracking solve.
  REQUIRE(run.finished_per_estimate.at(60) == run.options.window_size - 1);
  REQUIRE(run.finished.size() == static_cast<std::size_t>(run.options.window_size - 1));
  for (std::size_t k = 0; k < run.finished.size(); ++k) {
    if (k > 0) CHECK(run.finished[k].t_ns > run.finished[k - 1].t_ns);
    CHECK(run.finished[k].t_ns < run.estimates[59].t_ns);
    CHECK(!run.finished[k].image.empty());
    CHECK(!run.finished[k].points.empty());
  }
  // The window filled again after the reset: what is flushed at the end is newer than the reset.
  for (const Keyframe& kf : run.flushed) CHECK(kf.t_ns > run.estimates[60].t_ns);
}
