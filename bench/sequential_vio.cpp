#include "bench/sequential_vio.hpp"

#include <chrono>
#include <deque>

#include "stages/imu/imu_interval_builder.hpp"
#include "stages/tracker/stereo_tracker.hpp"

namespace dynavins::bench {

namespace {
eval::StampedPose stamped(int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  eval::StampedPose s;
  s.t_ns = t_ns;
  s.t = t_ns * 1e-9;
  s.p = p;
  s.q = q.normalized();
  return s;
}
}  // namespace

SequentialVioResult runSequentialVio(io::SensorSource& source, const EstimatorOptions& options,
                                     const estimator::EstimatorMode& mode,
                                     const std::function<void(const TrackedFrame&)>& on_tracked) {
  SequentialVioResult out;
  StereoTracker tracker(TrackerOptions::from(options), options.cameras.at(0),
                        mode.stereo ? options.cameras.at(1) : nullptr);
  ImuIntervalBuilderOptions io;
  io.noise = ImuNoiseParams{options.acc_n, options.gyr_n, options.acc_w, options.gyr_w};
  ImuIntervalBuilder imu(io);
  estimator::SlidingWindowEstimator est(options, mode);

  std::deque<TrackedFrame> waiting;  // tracked frames whose IMU interval has not completed yet
  std::map<int64_t, PreintegratedInterval> intervals;  // by end time
  bool first = true;
  auto consume = [&](std::vector<PreintegratedInterval> done) {
    for (auto& iv : done) intervals.emplace(iv.t_end_ns, std::move(iv));
    while (!waiting.empty()) {
      const TrackedFrame& f = waiting.front();
      const PreintegratedInterval* iv = nullptr;
      if (!first) {
        auto it = intervals.find(f.t_ns);
        if (it == intervals.end()) return;
        iv = &it->second;
      }
      const auto e = est.process(f, iv);
      first = false;
      ++out.frames;
      if (e.status == estimator::EstimatorStatus::Reset) ++out.resets;
      if (e.status == estimator::EstimatorStatus::Tracking) {
        ++out.tracking_frames;
        if (e.standstill) out.standstill_t_ns.push_back(e.t_ns);
        out.estimate.poses.push_back(stamped(e.t_ns, e.state.p_wb, e.state.q_wb));
        if (e.solve.alternations > 0) out.ba_ms.push_back(e.solve.ba_ms);
        for (const auto& wf : e.features.features) out.features[wf.id] = {wf.weight, wf.sim_label, wf.times_solved};
      }
      intervals.erase(intervals.begin(), intervals.upper_bound(f.t_ns));
      waiting.pop_front();
    }
  };

  SensorEvent ev;
  while (source.next(ev)) {
    if (auto* s = std::get_if<ImuSample>(&ev)) {
      consume(imu.addImu(*s));
    } else if (auto* g = std::get_if<GroundTruthState>(&ev)) {
      out.ground_truth.poses.push_back(stamped(g->t_ns, g->p_wb, g->q_wb));
      if (g->has_velocity) out.true_speed[g->t_ns] = g->v_wb.norm();
    } else if (auto* fr = std::get_if<StereoFrame>(&ev)) {
      StereoFrame frame = *fr;
      if (!mode.stereo) frame.right = cv::Mat();
      const auto t0 = std::chrono::steady_clock::now();
      waiting.push_back(tracker.process(frame));
      if (on_tracked) on_tracked(waiting.back());
      out.tracker_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      consume(imu.addFrame(frame.t_ns));
    }
  }
  return out;
}

WeightScore scoreWeights(const std::map<int64_t, FeatureOutcome>& features) {
  WeightScore s;
  int moving_low = 0, static_high = 0;
  for (const auto& [id, f] : features) {
    if (f.times_solved == 0 || f.sim_label < 0) continue;
    if (f.sim_label > 0) {
      ++s.moving;
      moving_low += f.weight < 0.5f;
    } else {
      ++s.static_;
      static_high += f.weight > 0.5f;
    }
  }
  s.moving_rejected = s.moving ? static_cast<double>(moving_low) / s.moving : 0;
  s.static_kept = s.static_ ? static_cast<double>(static_high) / s.static_ : 0;
  return s;
}

}  // namespace dynavins::bench
