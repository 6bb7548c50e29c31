// `dynavins replay (--euroc DIR | --log FILE) [--rate R]`: the replay driver alone, feeding a
// pipeline whose stages only count, to check a recording and measure the driver's pacing error.
#include <cstdio>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "bin/sensor_input.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/replay.hpp"
#include "pipeline/report_format.hpp"

namespace dynavins::cli {
namespace {

struct ReplayCommandOptions {
  SensorInput input;
  double rate = 1.0;
  int queue = 8;
};

/// Counts what arrives and checks it arrives in time order.
template <typename Msg>
struct OrderedCounter {
  int64_t count = 0, last = INT64_MIN, out_of_order = 0;
  void process(Msg m) {
    out_of_order += m.t_ns <= last;
    last = m.t_ns;
    ++count;
  }
};

void run_replay(const ReplayCommandOptions& o) {
  using namespace pipeline;
  auto source = o.input.open();
  const bool paced = o.rate > 0;
  Pipeline p;
  auto& frames = p.add_queue<StereoFrame>("frames", o.queue, paced ? Backpressure::DropOldest : Backpressure::Block);
  auto& imu = p.add_queue<ImuSample>("imu", 512, Backpressure::Block);
  ReplayStats stats;
  p.add_source(
      "replay",
      [&](const StopFlag& stop) {
        ReplaySinks sinks;
        sinks.frame = [&](StereoFrame&& f) { return frames.push(std::move(f)); };
        sinks.imu = [&](ImuSample&& s) {
          if (paced ? imu.try_push(s) : imu.push(s)) return true;
          if (stop.aborted()) return false;
          throw std::runtime_error("IMU queue full: IMU samples are never dropped");
        };
        stats = replay(*source, {o.rate, true}, sinks, stop);
      },
      [&] {
        frames.close();
        imu.close();
      });
  OrderedCounter<StereoFrame> frame_counter;
  OrderedCounter<ImuSample> imu_counter;
  p.add_stage("frames", frame_counter, frames, NoOutput{}, {});
  p.add_stage("imu", imu_counter, imu, NoOutput{}, {});
  const RunReport report = p.run();
  if (!report.ok) throw CommandError(report.error, 2);

  std::printf("%s", format_report(report).c_str());
  std::printf("source          %s\n", source->describe().c_str());
  std::printf("replayed        %lld stereo frames, %lld IMU samples, %lld ground-truth states\n",
              static_cast<long long>(stats.frames), static_cast<long long>(stats.imu),
              static_cast<long long>(stats.ground_truth));
  std::printf("time            %.3f s of data in %.3f s wall: %.2fx real time%s\n", stats.sensor_s, stats.wall_s,
              stats.wall_s > 0 ? stats.sensor_s / stats.wall_s : 0.0, stats.stopped ? " (interrupted)" : "");
  if (paced)
    std::printf("pacing error    mean %.3f ms, p95 %.3f ms, max %.3f ms over %llu events (rate %g)\n",
                stats.pacing_error.mean_ms, stats.pacing_error.p95_ms, stats.pacing_error.max_ms,
                static_cast<unsigned long long>(stats.pacing_error.count), o.rate);
  if (frame_counter.out_of_order || imu_counter.out_of_order)
    throw CommandError("events arrived out of time order", 1);
}

}  // namespace

void add_replay_command(CLI::App& app) {
  auto o = std::make_shared<ReplayCommandOptions>();
  auto* cmd = app.add_subcommand("replay", "Replay a recording through the pipeline's queues; report counts and pacing");
  o->input.add_options(*cmd, /*with_log=*/true);
  cmd->add_option("--rate", o->rate, "x real time; 0 = as fast as possible (blocking, lossless)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--queue", o->queue, "Frame queue capacity")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->callback([o] {
    pipeline::install_interrupt_handler();
    run_replay(*o);
  });
}

}  // namespace dynavins::cli
