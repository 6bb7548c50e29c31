#include "pipeline/vio/vio_pipeline.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>
#include <variant>

#include <spdlog/spdlog.h>

#include "pipeline/emit.hpp"
#include "pipeline/latest_value.hpp"
#include "pipeline/vio/frame_imu_attacher.hpp"
#include "stages/estimator/estimator_input.hpp"
#include "stages/tracker/gyro_rotation_predictor.hpp"
#include "stages/tracker/stereo_tracker.hpp"

namespace dynavins::pipeline {
namespace {

using estimator::EstimatorInput;
using estimator::WindowEstimate;

/// Tracker thread: the KLT front end; in mono mode the right image is ignored. With a predictor, each
/// frame's KLT starts from the rotation its gyro samples give since the previous tracked frame.
struct TrackerStage {
  TrackerStage(StereoTracker t, bool mono_, std::optional<GyroRotationPredictor> g, LatestValue<Eigen::Vector3d>& b)
      : tracker(std::move(t)), mono(mono_), gyro(std::move(g)), gyro_bias(b) {}

  StereoTracker tracker;
  bool mono;
  std::optional<GyroRotationPredictor> gyro;  ///< empty: prediction off
  /// The estimator's newest gyro bias. A LatestValue has one reader and the IMU thread reads the
  /// NavState one, so the estimator publishes the bias a second time, for this thread alone.
  LatestValue<Eigen::Vector3d>& gyro_bias;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  // zero until the estimator tracks
  std::optional<int64_t> prev_t_ns;
  int64_t frames_predicted = 0, frames_unpredicted = 0, features_predicted = 0, features_tracked = 0;
  int64_t features_lost_flow = 0, features_lost_back = 0;

  TrackedFrame process(TrackerInput in) {
    if (mono) in.frame.right = cv::Mat();
    std::optional<Eigen::Matrix3d> R_prev_curr;
    if (gyro) {
      if (const auto b = gyro_bias.read()) bias = *b;
      if (prev_t_ns) R_prev_curr = gyro->predict(in.imu, *prev_t_ns, in.frame.t_ns, bias);
      ++(R_prev_curr ? frames_predicted : frames_unpredicted);
    }
    prev_t_ns = in.frame.t_ns;
    TrackedFrame out = tracker.process(in.frame, R_prev_curr);
    features_predicted += out.stats.predicted;
    features_tracked += out.stats.tracked;
    features_lost_flow += out.stats.lost_flow;
    features_lost_back += out.stats.lost_back;
    return out;
  }
};

/// IMU thread: before each input, linearise at the estimator's newest biases (read without waiting).
struct ImuThreadStage {
  ImuStage stage;
  LatestValue<NavState>& latest;
  std::vector<PreintegratedInterval> process(ImuStageInput in) {
    if (const auto s = latest.read()) stage.setBiases(s->bias_acc, s->bias_gyr);
    return stage.process(in);
  }
};

/// Estimator thread: pairs frames with their IMU, runs the window BA, publishes the newest state.
struct EstimatorStage {
  FrameImuPairer pairer;
  estimator::SlidingWindowEstimator estimator;
  LatestValue<NavState>& latest;
  LatestValue<Eigen::Vector3d>& gyro_bias;  ///< the same state's gyro bias, for the tracker thread
  int64_t tracking = 0, resets = 0;

  std::vector<WindowEstimate> process(EstimatorInput in) {
    std::vector<FrameWithImu> ready =
        std::visit([this](auto&& x) -> std::vector<FrameWithImu> {
          using T = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, TrackedFrame>) return pairer.addFrame(std::move(x));
          else return pairer.addInterval(std::move(x));
        }, std::move(in));
    std::vector<WindowEstimate> out;
    out.reserve(ready.size());
    for (FrameWithImu& f : ready) {
      out.push_back(estimator.process(f.frame, f.imu ? &*f.imu : nullptr));
      const WindowEstimate& e = out.back();
      if (e.status == estimator::EstimatorStatus::Tracking) {
        ++tracking;
        const NavState s = estimator.latestState();
        latest.write(s);
        gyro_bias.write(s.bias_gyr);
      }
      if (e.status == estimator::EstimatorStatus::Reset) ++resets;
      if (!e.event.empty()) spdlog::info("estimator: t = {} ns: {}", e.t_ns, e.event);
    }
    return out;
  }
  void finish() { pairer.finish(); }
};

/// Writer thread: hands each estimate to the run's outputs.
struct WriterStage {
  const VioSinks& sinks;
  void process(WindowEstimate e) {
    if (sinks.estimate) sinks.estimate(e);
  }
};

}  // namespace

void checkVioOptions(const VioRunOptions& o) {
  if (!o.estimator.use_imu) throw std::invalid_argument("the config says imu: 0; `run` needs the IMU");
  if (o.estimator.cameras.empty()) throw std::invalid_argument("the config loads no camera");
  if (o.mode.stereo && (o.estimator.num_of_cam < 2 || o.estimator.cameras.size() < 2))
    throw std::invalid_argument("stereo needs num_of_cam: 2 in the config; use --mono for one camera");
  if (o.rate < 0) throw std::invalid_argument("rate must be >= 0");
  if (o.frame_queue == 0 || o.imu_queue == 0 || o.estimator_queue == 0 || o.output_queue == 0)
    throw std::invalid_argument("queue capacities must be positive");
}

VioRunResult runVio(io::SensorSource& source, const VioRunOptions& opt, const VioSinks& sinks,
                    const StopFlag* external_stop) {
  checkVioOptions(opt);
  const bool paced = opt.rate > 0;
  VioRunResult result;
  result.source = source.describe();

  const ImuStageOptions imu_options = ImuStageOptions::from(opt.estimator, opt.imu_rate_hz, opt.imu_noise);
  std::optional<GyroRotationPredictor> gyro;
  // estimate_extrinsic 2 lets a config leave body_T_cam0 out; the loader then stores identity, which is
  // no calibration: a gyro rotation conjugated by it would seed the KLT in the wrong direction.
  const bool extrinsic_known = opt.estimator.estimate_extrinsic != 2 || opt.estimator.keys_from_file.count("body_T_cam0");
  if (opt.gyro_prediction && !extrinsic_known)
    spdlog::warn("gyro prediction off: the config has no body_T_cam0 (estimate_extrinsic 2)");
  const bool predict = opt.gyro_prediction && extrinsic_known;
  // Same outage threshold as the IMU stage's interval builder.
  if (predict)
    gyro.emplace(opt.estimator.body_T_cam.at(0), std::llround(imu_options.gap_periods * 1e9 / imu_options.imu_rate_hz));
  LatestValue<NavState> latest;
  LatestValue<Eigen::Vector3d> gyro_bias;
  TrackerStage tracker(StereoTracker(TrackerOptions::from(opt.estimator), opt.estimator.cameras[0],
                                     opt.mode.stereo ? opt.estimator.cameras[1] : nullptr),
                       !opt.mode.stereo, std::move(gyro), gyro_bias);
  ImuThreadStage imu{ImuStage(imu_options), latest};
  EstimatorStage est{FrameImuPairer{}, estimator::SlidingWindowEstimator(opt.estimator, opt.mode), latest, gyro_bias};
  WriterStage writer{sinks};

  Pipeline p;
  auto& frames = p.add_queue<TrackerInput>("frames", opt.frame_queue, paced ? Backpressure::DropOldest : Backpressure::Block);
  auto& imu_in = p.add_queue<ImuStageInput>("imu", opt.imu_queue, Backpressure::Block);
  auto& est_in = p.add_fan_in<EstimatorInput>("estimator_in", opt.estimator_queue, Backpressure::Block);
  auto& estimates = p.add_queue<WindowEstimate>("estimates", opt.output_queue, Backpressure::Block);
  auto from_tracker = est_in.make_producer();
  auto from_imu = est_in.make_producer();

  p.add_source(
      "replay",
      [&](const StopFlag& stop) {
        auto stop_if_asked = [&] {
          if (external_stop && external_stop->stop_requested() && !stop.stop_requested()) {
            spdlog::warn("stop requested: stopping the replay and draining the queues");
            p.request_stop();
          }
        };
        // IMU input is never dropped: paced, a full queue is an error rather than a silent wait.
        auto push_imu = [&](ImuStageInput x) {
          if (paced ? imu_in.try_push(std::move(x)) : imu_in.push(std::move(x))) return true;
          if (stop.aborted()) return false;
          throw std::runtime_error("IMU queue full: the IMU stage fell behind (IMU is never dropped)");
        };
        // With prediction, a frame waits here for the first IMU sample at or after it (see FrameImuAttacher).
        FrameImuAttacher attacher;
        auto push_frame = [&](std::optional<TrackerInput> f) { return !f || frames.push(std::move(*f)); };
        ReplaySinks s;
        s.frame = [&](StereoFrame&& f) {
          stop_if_asked();
          if (!push_imu(FrameTime{f.t_ns})) return false;
          if (!predict) return frames.push(TrackerInput{std::move(f), {}});
          return push_frame(attacher.addFrame(std::move(f)));
        };
        s.imu = [&](ImuSample&& x) {
          stop_if_asked();
          if (!predict) return push_imu(std::move(x));
          const ImuSample copy = x;
          return push_imu(std::move(x)) && push_frame(attacher.addImu(copy));
        };
        s.ground_truth = [&](GroundTruthState&& g) {
          result.ground_truth.push_back(std::move(g));
          return true;
        };
        result.replay = replay(source, {opt.rate, opt.show_progress}, s, stop);
        push_frame(attacher.finish());
      },
      [&] {
        frames.close();
        imu_in.close();
      });
  p.add_stage("tracker", tracker, frames, into(*from_tracker), [&] { from_tracker->close(); });
  p.add_stage("imu", imu, imu_in, into(*from_imu), [&] { from_imu->close(); });
  p.add_stage("estimator", est, est_in, into(estimates), [&] { estimates.close(); });
  p.add_stage("writer", writer, estimates, NoOutput{}, {});

  result.report = p.run();

  for (const auto& q : result.report.queues)
    if (q.name == "frames") result.frames_dropped = static_cast<int64_t>(q.dropped);
  for (const auto& s : result.report.stages) {
    if (s.name == "tracker") result.frames_tracked = static_cast<int64_t>(s.processed);
  }
  result.gyro_prediction = predict;
  result.frames_gyro_predicted = tracker.frames_predicted;
  result.frames_gyro_unpredicted = tracker.frames_unpredicted;
  result.features_gyro_predicted = tracker.features_predicted;
  result.features_tracked = tracker.features_tracked;
  result.features_lost_flow = tracker.features_lost_flow;
  result.features_lost_back = tracker.features_lost_back;
  result.frames_estimated = est.pairer.stats().emitted;
  result.frames_tracking = est.tracking;
  result.resets = est.resets;
  result.imu = imu.stage.stats();
  result.imu_builder = imu.stage.builderStats();
  result.pairer = est.pairer.stats();
  return result;
}

}  // namespace dynavins::pipeline
