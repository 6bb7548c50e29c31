#include "pipeline/vio/vio_stages.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>
#include <variant>

#include <spdlog/spdlog.h>

#include "pipeline/clock.hpp"
#include "pipeline/vio/vio_pipeline.hpp"

namespace dynavins::pipeline {

TrackerStage::TrackerStage(tracker::StereoTracker t, bool mono_, std::optional<tracker::GyroRotationPredictor> g,
                           LatestValue<Eigen::Vector3d>& b, std::function<void(const TrackedFrame&)> cb)
    : tracker(std::move(t)), mono(mono_), gyro(std::move(g)), gyro_bias(b), on_tracked(std::move(cb)) {}

TrackedFrame TrackerStage::process(TrackerInput in) {
  const int64_t received_ns = steady_now_ns();
  if (mono) in.frame.right = cv::Mat();
  std::optional<Eigen::Matrix3d> R_prev_curr;
  if (gyro) {
    if (const auto b = gyro_bias.read()) bias = *b;
    if (prev_t_ns) R_prev_curr = gyro->predict(in.imu, *prev_t_ns, in.frame.t_ns, bias);
    ++(R_prev_curr ? frames_predicted : frames_unpredicted);
  }
  prev_t_ns = in.frame.t_ns;
  if (rejected) {
    std::vector<int64_t> ids;
    if (!wait_for_verdict || in.finishable_before < 0) ids = rejected->latest();
    else if (!rejected->wait(in.finishable_before, std::chrono::seconds(60), &ids))
      spdlog::warn("tracker: no verdict from the estimator on {} frames within 60 s; tracking on without it",
                   in.finishable_before);
    tracker.set_rejected(std::move(ids));
  }
  TrackedFrame out = tracker.process(in.frame, R_prev_curr);
  out.received_ns = received_ns;
  features_predicted += out.stats.predicted;
  features_tracked += out.stats.tracked;
  features_lost_flow += out.stats.lost_flow;
  features_lost_back += out.stats.lost_back;
  if (on_tracked) on_tracked(out);
  return out;
}

std::vector<PreintegratedInterval> ImuFeedbackStage::process(imu::ImuStageInput in) {
  const int64_t origin_ns = on_imu_pose ? steady_now_ns() : 0;
  const auto s = latest.read();
  if (s) stage.set_biases(s->bias_acc, s->bias_gyr);
  if (on_imu_pose) {
    if (s && s->t_ns != propagated_from_ns) {
      propagator.reset(*s);
      propagated_from_ns = s->t_ns;
    }
    const auto* sample = std::get_if<ImuSample>(&in);
    if (sample && s && sample->t_ns - propagated_from_ns <= max_propagation_ns)
      if (const auto p = propagator.add_imu(*sample)) on_imu_pose(PoseEstimate{PoseSource::ImuRate, *p}, origin_ns);
  }
  return stage.process(in);
}

std::vector<estimator::WindowEstimate> EstimatorStage::process(estimator::EstimatorInput in) {
  std::vector<imu::FrameWithImu> ready =
      std::visit([this](auto&& x) -> std::vector<imu::FrameWithImu> {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, TrackedFrame>) return pairer.add_frame(std::move(x));
        else return pairer.add_interval(std::move(x));
      }, std::move(in));
  std::vector<estimator::WindowEstimate> out;
  out.reserve(ready.size());
  for (imu::FrameWithImu& f : ready) {
    out.push_back(estimator.process(f.frame, f.imu ? &*f.imu : nullptr));
    out.back().received_ns = f.frame.received_ns;
    for (Keyframe& kf : out.back().finished_keyframes)
      if (on_keyframe) on_keyframe(std::move(kf));
    out.back().finished_keyframes.clear();  // the images go no further than the loop closer
    const estimator::WindowEstimate& e = out.back();
    if (e.status == estimator::EstimatorStatus::Tracking) {
      ++tracking;
      const NavState s = estimator.latest_state();
      latest.write(s);
      gyro_bias.write(s.bias_gyr);
    }
    if (e.status == estimator::EstimatorStatus::Reset) ++resets;
    if (!e.event.empty()) spdlog::info("estimator: t = {} ns: {}", e.t_ns, e.event);
  }
  if (rejected) {
    // Frames received and no longer waiting for their IMU (emitted, skipped or ignored) are finished.
    const int64_t done = pairer.stats().frames_in - static_cast<int64_t>(pairer.waiting_frames());
    if (out.empty()) {
      rejected->finished(done);
    } else {
      // Verdicts judged on the IMU path from a rest are not fed back: that path drifts with the
      // accelerometer bias (5 % short after 2.6 s on the drive-off draw, street_follow seed 26), so it
      // rejects static tracks for seconds, and fed back those would steer fresh corners onto the truck.
      std::vector<int64_t> ids;
      if (!out.back().judged_on_rest_path)
        for (const auto& f : out.back().features.features)
          if (f.weight < 0.5f) ids.push_back(f.id);
      rejected->publish(done, std::move(ids));
    }
  }
  return out;
}

void EstimatorStage::finish() {
  if (rejected) rejected->close();
  pairer.finish();
  std::vector<Keyframe> rest = estimator.flush_keyframes();
  if (on_keyframe)
    for (Keyframe& kf : rest) on_keyframe(std::move(kf));
}

void WriterStage::process(estimator::WindowEstimate e) {
  if (sink) sink(e);
  ++frames;
  resets += e.status == estimator::EstimatorStatus::Reset;
  if (!publish) return;
  // Every frame: the publisher sends a change at once and the current status once a second.
  publish(PublishItem{0, StatusUpdate{e.t_ns, e.status, e.event, frames, resets}});
  if (e.status != estimator::EstimatorStatus::Tracking) return;
  publish(PublishItem{e.received_ns, PoseEstimate{PoseSource::Window, e.state}});
  if (correct)
    if (const auto c = correct(e.state)) publish(PublishItem{0, PoseEstimate{PoseSource::LoopCorrected, *c}});
  publish(PublishItem{0, std::move(e.features)});
}

namespace {

// estimate_extrinsic 2 lets a config leave body_T_cam0 out; the loader then stores identity, which is no
// calibration: a gyro rotation conjugated by it would seed the KLT in the wrong direction.
bool gyro_prediction_usable(const VioRunOptions& o) {
  const bool extrinsic_known = o.estimator.estimate_extrinsic != 2 || o.estimator.keys_from_file.count("body_T_cam0");
  if (o.gyro_prediction && !extrinsic_known)
    spdlog::warn("gyro prediction off: the config has no body_T_cam0 (estimate_extrinsic 2)");
  return o.gyro_prediction && extrinsic_known;
}

std::optional<tracker::GyroRotationPredictor> gyro_predictor(const VioRunOptions& o, bool predict) {
  if (!predict) return std::nullopt;
  // Same outage threshold as the IMU stage's interval builder.
  const imu::ImuStageOptions imu = imu::ImuStageOptions::from(o.estimator, o.imu_rate_hz, o.imu_noise);
  return tracker::GyroRotationPredictor(o.estimator.body_T_cam.at(0), std::llround(imu.gap_periods * 1e9 / imu.imu_rate_hz));
}

// As fast as possible (rate 0) the run must not depend on how fast or loaded the machine is, so each
// window solve is bounded by its iteration budget alone; the config's wall-clock budget
// (max_solver_time) applies to paced runs, where the estimator must keep up.
EstimatorOptions estimator_options(const VioRunOptions& o) {
  EstimatorOptions e = o.estimator;
  if (!o.real_time()) e.max_solver_time = std::numeric_limits<double>::infinity();
  return e;
}

}  // namespace

VioStages::VioStages(const VioRunOptions& o, std::function<void(const TrackedFrame&)> on_tracked,
                     std::function<void(const estimator::WindowEstimate&)> on_estimate)
    : predict(gyro_prediction_usable(o)),
      solver_time_budget(o.real_time()),
      tracker(tracker::StereoTracker(tracker::TrackerOptions::from(o.estimator), o.estimator.cameras.at(0),
                            o.mode.stereo ? o.estimator.cameras.at(1) : nullptr),
              !o.mode.stereo, gyro_predictor(o, predict), gyro_bias, std::move(on_tracked)),
      imu{imu::ImuStage(imu::ImuStageOptions::from(o.estimator, o.imu_rate_hz, o.imu_noise)), latest, {},
          imu::ImuPropagator(imu::ImuPropagatorOptions{o.estimator.g_norm})},
      estimator{imu::FrameImuPairer{}, estimator::SlidingWindowEstimator(estimator_options(o), o.mode), latest, gyro_bias},
      writer{std::move(on_estimate), {}, {}, 0, 0} {
  if (o.loop_mode != loop::LoopMode::Off)
    loop = std::make_unique<LoopStage>(o.loop_mode, o.vocabulary, o.estimator.cameras.at(0));
  if (o.estimator.rejected_feedback && o.mode.loss == estimator::BaLoss::Dynavins) {
    tracker.rejected = &rejected;
    tracker.wait_for_verdict = !o.real_time();
    estimator.rejected = &rejected;
  }
}

void VioStages::collect(VioRunResult& r) const {
  r.gyro_prediction = predict;
  r.solver_time_budget = solver_time_budget;
  r.frames_gyro_predicted = tracker.frames_predicted;
  r.frames_gyro_unpredicted = tracker.frames_unpredicted;
  r.features_gyro_predicted = tracker.features_predicted;
  r.features_tracked = tracker.features_tracked;
  r.features_lost_flow = tracker.features_lost_flow;
  r.features_lost_back = tracker.features_lost_back;
  r.frames_estimated = estimator.pairer.stats().emitted;
  r.frames_tracking = estimator.tracking;
  r.resets = estimator.resets;
  r.imu = imu.stage.stats();
  r.imu_builder = imu.stage.builder_stats();
  r.pairer = estimator.pairer.stats();
  if (loop) r.loop = loop->summary();
}

}  // namespace dynavins::pipeline
