#include "pipeline/vio/vio_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "pipeline/clock.hpp"
#include "pipeline/emit.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/vio/frame_imu_attacher.hpp"
#include "pipeline/latest_value.hpp"
#include "stages/loop/loop_closer.hpp"
#include "pipeline/vio/vio_stages.hpp"

namespace dynavins::pipeline {
namespace {

using estimator::EstimatorInput;
using estimator::WindowEstimate;

/// The replay's hand-over, the same for both drivers: each frame's time goes to the IMU stage before the
/// frame goes to the tracker, so the interval that ends at a frame is complete when the frame is. With
/// gyro prediction a frame waits in `attacher` for the first IMU sample at or after it. Each push returns
/// false when the run is aborted; `poll` runs before every event (stop requests).
struct ReplayRouting {
  bool predict = false;
  /// The config's td [ns] (image clock + td = IMU clock, VINS-Fusion's convention): every frame's time is
  /// moved into the IMU's clock as it arrives, so the IMU interval of a frame ends when it was taken, and
  /// every output is in the IMU's clock, where EuRoC's ground truth is.
  int64_t td_ns = 0;
  std::function<bool(imu::ImuStageInput)> push_imu;
  std::function<bool(TrackerInput)> push_frame;
  std::function<void()> poll;
  std::vector<GroundTruthState>* ground_truth = nullptr;
  FrameImuAttacher attacher;

  // Frames handed to the tracker so far, the times of those an IMU sample has not yet reached, and the
  // newest IMU sample time (TrackerInput::finishable_before).
  int64_t frames_pushed = 0;
  std::deque<int64_t> unfinishable;
  int64_t last_imu_ns = INT64_MIN;

  bool push_tracked(TrackerInput f) {
    while (!unfinishable.empty() && unfinishable.front() <= last_imu_ns) unfinishable.pop_front();
    f.finishable_before = frames_pushed - static_cast<int64_t>(unfinishable.size());
    unfinishable.push_back(f.frame.t_ns);
    ++frames_pushed;
    return push_frame(std::move(f));
  }
  bool push_attached(std::optional<TrackerInput> f) { return !f || push_tracked(std::move(*f)); }

  ReplaySinks sinks() {
    ReplaySinks s;
    s.frame = [this](StereoFrame&& f) {
      poll();
      f.t_ns += td_ns;
      if (!push_imu(imu::FrameTime{f.t_ns})) return false;
      if (!predict) return push_tracked(TrackerInput{std::move(f), {}});
      return push_attached(attacher.add_frame(std::move(f)));
    };
    s.imu = [this](ImuSample&& x) {
      poll();
      last_imu_ns = std::max(last_imu_ns, x.t_ns);
      if (!predict) return push_imu(std::move(x));
      const ImuSample copy = x;
      return push_imu(std::move(x)) && push_attached(attacher.add_imu(copy));
    };
    s.ground_truth = [this](GroundTruthState&& g) {
      ground_truth->push_back(std::move(g));
      return true;
    };
    return s;
  }
  /// End of the replay: the frame still waiting for its IMU goes on without it.
  void finish() { push_attached(attacher.finish()); }
};

int64_t td_ns(const EstimatorOptions& o) { return std::llround(o.td * 1e9); }

/// The loop closer's output for the publisher: after an optimisation the keyframe path and each group's
/// hypotheses; always the newest drift, for the loop-corrected window pose.
void publish_loop_output(const loop::LoopCloserOutput& out, const loop::LoopCloser& closer,
                       FanInQueue<PublishItem>::Producer& pub, LatestValue<loop::RigidPose>& drift) {
  drift.write(out.drift);
  if (!out.optimized) return;
  PathUpdate path;
  path.t_ns = out.t_ns;
  for (std::size_t i = 0; i < out.corrected.size() && i < out.keyframe_t_ns.size(); ++i) {
    PoseEstimate p;
    p.source = PoseSource::LoopCorrected;
    p.state.t_ns = out.keyframe_t_ns[i];
    p.state.p_wb = out.corrected[i].p;
    p.state.q_wb = out.corrected[i].q;
    path.poses.push_back(p);
  }
  for (const loop::HypothesisReport& h : out.hypotheses) {
    HypothesesUpdate u;
    u.t_ns = out.t_ns;
    u.group_first_t_ns = h.group_first_t_ns;
    if (h.group >= 0 && static_cast<std::size_t>(h.group) < closer.groups().size())
      u.group_size = static_cast<int32_t>(closer.groups()[static_cast<std::size_t>(h.group)].t_ns.size());
    NavState first;
    for (const PoseEstimate& p : path.poses)
      if (p.state.t_ns == h.group_first_t_ns) first = p.state;
    for (const auto& [indices, w] : {std::pair{&h.h0, h.w0}, {&h.h1, h.w1}}) {
      if (indices->empty()) continue;
      HypothesesUpdate::Hypothesis hyp;
      hyp.weight = static_cast<float>(w);
      hyp.first_keyframe = first;
      for (std::size_t i : *indices)
        if (i < closer.loops().size()) hyp.loops.emplace_back(closer.loops()[i].query_t_ns, closer.loops()[i].match_t_ns);
      u.hypotheses.push_back(std::move(hyp));
    }
    pub.push(PublishItem{0, std::move(u)});
  }
  pub.push(PublishItem{0, std::move(path)});
}

void count_frames(VioRunResult& result) {
  for (const auto& q : result.report.queues)
    if (q.name == "frames") result.frames_dropped = static_cast<int64_t>(q.dropped);
  for (const auto& s : result.report.stages)
    if (s.name == "tracker") result.frames_tracked = static_cast<int64_t>(s.processed);
}

}  // namespace

void check_vio_options(const VioRunOptions& o) {
  if (!o.estimator.use_imu) throw std::invalid_argument("the config says imu: 0; `run` needs the IMU");
  if (o.estimator.cameras.empty()) throw std::invalid_argument("the config loads no camera");
  if (o.mode.stereo && (o.estimator.num_of_cam < 2 || o.estimator.cameras.size() < 2))
    throw std::invalid_argument("stereo needs num_of_cam: 2 in the config; use --mono for one camera");
  if (o.rate < 0) throw std::invalid_argument("rate must be >= 0");
  if (o.live && o.rate != 0) throw std::invalid_argument("a live source is not paced: rate must be 0");
  if (o.frame_queue == 0 || o.imu_queue == 0 || o.estimator_queue == 0 || o.output_queue == 0 ||
      o.publish_queue == 0)
    throw std::invalid_argument("queue capacities must be positive");
}

VioRunResult run_vio(io::SensorSource& source, const VioRunOptions& opt, const VioSinks& sinks,
                    const StopFlag* external_stop) {
  check_vio_options(opt);
  const bool paced = opt.real_time();
  VioRunResult result;
  result.source = source.describe();
  VioStages st(opt, sinks.tracked, sinks.estimate);

  Pipeline p;
  auto& frames = p.add_queue<TrackerInput>("frames", opt.frame_queue, paced ? Backpressure::DropOldest : Backpressure::Block);
  auto& imu_in = p.add_queue<imu::ImuStageInput>("imu", opt.imu_queue, Backpressure::Block);
  auto& est_in = p.add_fan_in<EstimatorInput>("estimator_in", opt.estimator_queue, Backpressure::Block);
  auto& estimates = p.add_queue<WindowEstimate>("estimates", opt.output_queue, Backpressure::Block);
  auto from_tracker = est_in.make_producer();
  auto from_imu = est_in.make_producer();

  // The publisher: IMU-rate poses from the IMU thread, the rest from the writer's; it never blocks them.
  std::unique_ptr<LcmPublisher> publisher;
  FanInQueue<PublishItem>* publish_q = nullptr;
  std::unique_ptr<FanInQueue<PublishItem>::Producer> imu_pub, writer_pub;
  if (!opt.lcm_url.empty()) {
    const int64_t t0 = steady_now_ns();
    publisher = std::make_unique<LcmPublisher>(opt.lcm_url, opt.channels, [&p, t0] {
      RunReport r;
      r.stages = p.stage_stats();
      r.queues = p.queue_stats();
      r.wall_s = static_cast<double>(steady_now_ns() - t0) / 1e9;
      return r;
    });
    publish_q = &p.add_fan_in<PublishItem>("publish", opt.publish_queue, Backpressure::DropNewest);
    imu_pub = publish_q->make_producer();
    writer_pub = publish_q->make_producer();
    st.imu.on_imu_pose = [&](const PoseEstimate& pose, int64_t origin) { imu_pub->push(PublishItem{origin, pose}); };
    st.writer.publish = [&](PublishItem item) { writer_pub->push(std::move(item)); };
  }

  p.add_source(
      "replay",
      [&](const StopFlag& stop) {
        ReplayRouting route;
        route.predict = st.predict;
        route.td_ns = td_ns(opt.estimator);
        route.ground_truth = &result.ground_truth;
        route.poll = [&] {
          if (external_stop && external_stop->stop_requested() && !stop.stop_requested()) {
            spdlog::warn("stop requested: stopping the replay and draining the queues");
            p.request_stop();
          }
        };
        // IMU input is never dropped: paced, a full queue is an error rather than a silent wait.
        route.push_imu = [&](imu::ImuStageInput x) {
          if (paced ? imu_in.try_push(std::move(x)) : imu_in.push(std::move(x))) return true;
          if (stop.aborted()) return false;
          throw std::runtime_error("IMU queue full: the IMU stage fell behind (IMU is never dropped)");
        };
        route.push_frame = [&](TrackerInput f) { return frames.push(std::move(f)); };
        result.replay = replay(source, {opt.rate, opt.show_progress}, route.sinks(), stop);
        route.finish();
      },
      [&] {
        frames.close();
        imu_in.close();
      });
  p.add_stage("tracker", st.tracker, frames, into(*from_tracker), [&] { from_tracker->close(); });
  p.add_stage("imu", st.imu, imu_in, into(*from_imu), [&] {
    from_imu->close();
    if (imu_pub) imu_pub->close();
  });
  // Loop outputs for the publisher: the path and hypotheses of each optimisation from the loop thread,
  // the drift through a snapshot that the writer applies to each window pose.
  LatestValue<loop::RigidPose> drift;
  std::unique_ptr<FanInQueue<PublishItem>::Producer> loop_pub;
  if (publisher && st.loop) {
    loop_pub = publish_q->make_producer();
    st.loop->on_output = [&](const loop::LoopCloserOutput& out) { publish_loop_output(out, st.loop->closer(), *loop_pub, drift); };
    st.writer.correct = [&drift](const NavState& s) -> std::optional<NavState> {
      const auto d = drift.read();
      if (!d) return std::nullopt;
      NavState c = s;
      c.p_wb = d->p + d->q * s.p_wb;
      c.q_wb = (d->q * s.q_wb).normalized();
      c.v_wb = d->q * s.v_wb;
      return c;
    };
  }
  // The loop closer: keyframes leave the estimator's thread through their own queue (lossless at rate 0;
  // in real time a full queue drops the keyframe and counts it rather than stall the estimator).
  SpscQueue<Keyframe>* keyframes = nullptr;
  if (sinks.keyframe) st.estimator.on_keyframe = [&](Keyframe&& kf) { sinks.keyframe(kf); };
  if (st.loop) {
    keyframes = &p.add_queue<Keyframe>("keyframes", opt.keyframe_queue, Backpressure::Block);
    st.estimator.on_keyframe = [&](Keyframe&& kf) {
      if (sinks.keyframe) sinks.keyframe(kf);
      if (paced ? keyframes->try_push(std::move(kf)) : keyframes->push(std::move(kf))) return;
      if (!p.stop_flag().aborted()) ++st.loop->dropped;
    };
  }
  p.add_stage("estimator", st.estimator, est_in, into(estimates), [&] {
    st.rejected.close();  // a tracker waiting for a verdict goes on (also when the estimator failed)
    estimates.close();
    if (keyframes) keyframes->close();
  });
  if (st.loop) p.add_stage("loop", *st.loop, *keyframes, NoOutput{}, [&] {
    if (loop_pub) loop_pub->close();
  });
  p.add_stage("writer", st.writer, estimates, NoOutput{}, [&] {
    if (writer_pub) writer_pub->close();
  });
  if (publisher) p.add_stage("publisher", *publisher, *publish_q, NoOutput{}, {});
  // The source too: live, it drains the sensor socket, and a starved reader loses IMU packets in the kernel.
  if (opt.real_time() && opt.realtime_priority > 0) {
    p.set_thread_realtime("replay", opt.realtime_priority);
    p.set_thread_realtime("imu", opt.realtime_priority);
    if (publisher) p.set_thread_realtime("publisher", opt.realtime_priority);
  }

  result.report = p.run();
  result.realtime_threads = p.realtime_threads();
  result.realtime_refused = p.realtime_refused();
  if (publisher) {
    result.publisher = publisher->stats();
    for (const auto& q : result.report.queues)
      if (q.name == "publish") result.publish_dropped = static_cast<int64_t>(q.dropped);
  }
  count_frames(result);
  st.collect(result);
  return result;
}

VioRunResult run_vio_sequential(io::SensorSource& source, const VioRunOptions& opt, const VioSinks& sinks,
                              const StopFlag* external_stop) {
  check_vio_options(opt);
  if (opt.rate != 0) throw std::invalid_argument("the sequential run replays as fast as possible: rate must be 0");
  if (!opt.lcm_url.empty()) throw std::invalid_argument("the sequential run does not publish: use run_vio for lcm_url");
  VioRunResult result;
  result.source = source.describe();
  VioStages st(opt, sinks.tracked, sinks.estimate);
  // One thread: whatever the estimator can finish is finished before the tracker runs, so the tracker
  // takes the newest verdict. Waiting could only stall, on a frame the IMU pairing still holds (the first
  // one, when the IMU starts after it): 60 s, then on without it.
  st.tracker.wait_for_verdict = false;

  const char* stage = "replay";  // the stage running now, for the report of a failure
  auto toEstimator = [&](EstimatorInput in) {
    stage = "estimator";
    for (WindowEstimate& e : st.estimator.process(std::move(in))) {
      stage = "writer";
      st.writer.process(std::move(e));
    }
    stage = "replay";
  };
  if (sinks.keyframe) st.estimator.on_keyframe = [&](Keyframe&& kf) { sinks.keyframe(kf); };
  if (st.loop)
    st.estimator.on_keyframe = [&](Keyframe&& kf) {
      if (sinks.keyframe) sinks.keyframe(kf);
      stage = "loop";
      st.loop->process(std::move(kf));
      stage = "estimator";
    };
  StopFlag stop;
  bool interrupted = false;
  ReplayRouting route;
  route.predict = st.predict;
  route.td_ns = td_ns(opt.estimator);
  route.ground_truth = &result.ground_truth;
  route.poll = [&] {
    const bool asked = (external_stop && external_stop->stop_requested()) || interrupt_requested();
    if (asked && !stop.stop_requested()) {
      spdlog::warn("stop requested: stopping the replay");
      interrupted = true;
      stop.request_stop();
    }
  };
  route.push_imu = [&](imu::ImuStageInput x) {
    stage = "imu";
    for (PreintegratedInterval& iv : st.imu.process(std::move(x))) toEstimator(std::move(iv));
    stage = "replay";
    return true;
  };
  int64_t tracked = 0;
  route.push_frame = [&](TrackerInput f) {
    stage = "tracker";
    TrackedFrame t = st.tracker.process(std::move(f));
    ++tracked;
    toEstimator(std::move(t));
    return true;
  };

  const auto t0 = std::chrono::steady_clock::now();
  try {
    result.replay = replay(source, {0.0, opt.show_progress}, route.sinks(), stop);
    route.finish();
    stage = "estimator";
    st.estimator.finish();
    if (st.loop) {
      stage = "loop";
      st.loop->finish();
    }
  } catch (const std::exception& e) {
    result.report.ok = false;
    result.report.failed_thread = stage;
    result.report.error = e.what();
  }
  result.report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.report.interrupted = interrupted;
  result.frames_tracked = tracked;
  st.collect(result);
  return result;
}

}  // namespace dynavins::pipeline
