#include "pipeline/replay.hpp"

#include <cmath>
#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "pipeline/clock.hpp"
#include "pipeline/progress.hpp"

namespace dynavins::pipeline {

ReplayStats replay(io::SensorSource& source, const ReplayOptions& options, const ReplaySinks& sinks,
                   const StopFlag& stop) {
  ReplayStats stats;
  LatencyHistogram pacing;
  Progress progress("replay");
  const bool paced = options.rate > 0.0;
  const int64_t wall0 = steady_now_ns();
  int64_t t0 = 0, t_last = 0;
  bool first = true;

  SensorEvent event;
  while (!stop.stop_requested() && source.next(event)) {
    const int64_t t = event_time_ns(event);
    if (first) t0 = t, first = false;
    t_last = t;
    if (paced) {
      const int64_t due = wall0 + static_cast<int64_t>(std::llround(static_cast<double>(t - t0) / options.rate));
      const int64_t ahead = due - steady_now_ns();
      if (ahead > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(ahead));
      pacing.record(std::abs(steady_now_ns() - due));
    }
    bool taken = true;
    if (auto* f = std::get_if<StereoFrame>(&event)) {
      taken = sinks.frame(std::move(*f));
      ++stats.frames;
    } else if (auto* s = std::get_if<ImuSample>(&event)) {
      taken = sinks.imu(std::move(*s));
      ++stats.imu;
    } else {
      if (sinks.ground_truth) taken = sinks.ground_truth(std::move(std::get<GroundTruthState>(event)));
      ++stats.ground_truth;
    }
    if (!taken && stop.aborted()) break;
    if (options.show_progress) {
      const double sensor = static_cast<double>(t - t0) / 1e9;
      const double wall = static_cast<double>(steady_now_ns() - wall0) / 1e9;
      progress.update(source.progress(), fmt::format("{} frames  {:.1f} s of data  {:.2f}x real time", stats.frames,
                                                     sensor, wall > 0 ? sensor / wall : 0.0));
    }
  }
  stats.stopped = stop.stop_requested();
  stats.sensor_s = static_cast<double>(t_last - t0) / 1e9;
  stats.wall_s = static_cast<double>(steady_now_ns() - wall0) / 1e9;
  stats.pacing_error = pacing.summary();
  if (options.show_progress)
    progress.done(fmt::format("{} frames, {} IMU samples, {} ground-truth states, {:.1f} s of data in {:.1f} s{}",
                              stats.frames, stats.imu, stats.ground_truth, stats.sensor_s, stats.wall_s,
                              stats.stopped ? " (stopped early)" : ""));
  return stats;
}

}  // namespace dynavins::pipeline
