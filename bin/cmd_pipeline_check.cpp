// `dynavins pipeline-check`: runs a synthetic sensor stream through the real stage-thread framework
// (source -> tracker-like and IMU-like stages -> fan-in -> publisher-like sink) and checks what
// the framework promises: nothing lost or reordered when blocking, drops counted when paced in
// real time, every queue bounded and drained. Prints the per-thread and per-queue table and
// writes summary.json and the stats as an LCM log when --out is given.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>
#include <variant>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "messages/sensor_messages.hpp"
#include "pipeline/clock.hpp"
#include "pipeline/interrupt.hpp"
#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_log.hpp"
#include "pipeline/pipeline.hpp"
#include "pipeline/report_format.hpp"

namespace dynavins::cli {
namespace {

using namespace std::chrono_literals;

struct Options {
  int frames = 200;
  double rate = 0.0;
  double work_ms = 5.0;
  int queue = 4;
  std::string out;
};

struct FrameDigest {
  int64_t seq = 0;
  int64_t t_ns = 0;
};
struct ImuDigest {
  int64_t t_ns = 0;
  int samples = 0;
};
using Published = std::variant<FrameDigest, ImuDigest>;

/// Stands in for the tracker: costs `work_ms` a frame and reduces the frame to a digest.
struct FrameWork {
  double work_ms;
  FrameDigest process(StereoFrame f) {
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(work_ms));
    return {f.seq, f.t_ns};
  }
};

/// Stands in for IMU preintegration: one output per 10 samples (one frame interval at 200 Hz).
struct ImuWork {
  int pending = 0;
  std::optional<ImuDigest> process(ImuSample s) {
    if (++pending < 10) return std::nullopt;
    pending = 0;
    return ImuDigest{s.t_ns, 10};
  }
  std::optional<ImuDigest> finish() {  // flush a partial interval at end of stream
    if (pending == 0) return std::nullopt;
    return ImuDigest{-1, std::exchange(pending, 0)};
  }
};

/// Stands in for the publisher: checks that each producer's items arrive in order.
struct OrderCheck {
  int64_t frames = 0, imu_samples = 0, last_seq = -1, order_errors = 0;
  void process(Published p) {
    if (const auto* f = std::get_if<FrameDigest>(&p)) {
      if (f->seq <= last_seq) ++order_errors;
      last_seq = f->seq;
      ++frames;
    } else {
      imu_samples += std::get<ImuDigest>(p).samples;
    }
  }
};

void run_check(const Options& o) {
  using namespace pipeline;
  const bool paced = o.rate > 0;
  const int64_t imu_dt = 5'000'000;  // 200 Hz IMU; a frame every 10th sample (20 Hz)
  const int64_t imu_count = static_cast<int64_t>(o.frames) * 10;

  Pipeline p;
  auto& frames_q = p.add_queue<StereoFrame>("frames", o.queue, paced ? Backpressure::DropOldest : Backpressure::Block);
  auto& imu_q = p.add_queue<ImuSample>("imu", 64 * o.queue, Backpressure::Block);
  auto& pub_q = p.add_fan_in<Published>("publisher", 16 * o.queue, Backpressure::Block);
  auto from_tracker = pub_q.make_producer();
  auto from_imu = pub_q.make_producer();

  p.add_source(
      "replay",
      [&](const StopFlag& stop) {
        const int64_t start = steady_now_ns();
        for (int64_t k = 0; k < imu_count && !stop.stop_requested(); ++k) {
          const int64_t t = k * imu_dt;
          if (paced) {  // sleep until this sample's wall time
            const auto wall = static_cast<int64_t>(static_cast<double>(t) / o.rate);
            const int64_t ahead = start + wall - steady_now_ns();
            if (ahead > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(ahead));
          }
          ImuSample s;
          s.t_ns = t;
          s.acc = Eigen::Vector3d(0, 0, 9.81);
          if (paced ? !imu_q.try_push(s) : !imu_q.push(s)) {
            if (stop.aborted()) return;
            throw std::runtime_error("IMU queue full: IMU samples are never dropped (is the IMU stage stuck?)");
          }
          if (k % 10 == 0) {
            StereoFrame f;
            f.t_ns = t;
            f.seq = k / 10;
            f.left = cv::Mat(480, 752, CV_8UC1, cv::Scalar(static_cast<int>(f.seq % 256)));
            f.right = f.left.clone();
            frames_q.push(std::move(f));
          }
        }
      },
      [&] {
        frames_q.close();
        imu_q.close();
      });

  FrameWork tracker{o.work_ms};
  ImuWork imu;
  OrderCheck sink;
  p.add_stage("tracker", tracker, frames_q, into(*from_tracker), [&] { from_tracker->close(); });
  p.add_stage("imu", imu, imu_q, into(*from_imu), [&] { from_imu->close(); });
  p.add_stage("publisher", sink, pub_q, NoOutput{}, {});

  spdlog::info("pipeline-check: {} frames, {} IMU samples, {}, tracker {:.1f} ms/frame, queue capacity {}", o.frames,
               imu_count, paced ? fmt::format("paced at {}x real time (drop-oldest)", o.rate)
                                : std::string("as fast as possible (blocking)"),
               o.work_ms, o.queue);
  const RunReport report = p.run();
  std::printf("%s", format_report(report).c_str());

  // What the framework promises, checked on this run's own counters.
  const QueueStats fq = report.queues[0];
  std::vector<std::string> failures;
  if (!report.ok) failures.push_back("run failed in " + report.failed_thread + ": " + report.error);
  if (sink.order_errors) failures.push_back(std::to_string(sink.order_errors) + " frames arrived out of order");
  if (sink.imu_samples != imu_count && !report.interrupted)
    failures.push_back("IMU samples lost: " + std::to_string(imu_count - sink.imu_samples));
  if (static_cast<uint64_t>(sink.frames) != fq.delivered) failures.push_back("frames lost after the frame queue");
  if (fq.pushed != fq.delivered + fq.dropped) failures.push_back("frame queue: pushed != delivered + dropped");
  if (!paced && fq.dropped) failures.push_back("frames dropped in blocking mode");
  for (const auto& q : report.queues) {
    if (q.max_depth > q.capacity) failures.push_back("queue " + q.name + " exceeded its capacity");
    if (q.depth != 0) failures.push_back("queue " + q.name + " not drained");
  }
  const double sensor_s = static_cast<double>(imu_count * imu_dt) / 1e9;
  std::printf("frames: %lld delivered, %llu dropped; real-time factor %.2fx; %s\n",
              static_cast<long long>(sink.frames), static_cast<unsigned long long>(fq.dropped),
              sensor_s / report.wall_s, failures.empty() ? "all checks passed" : "CHECKS FAILED");

  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    const auto wall_utime = std::chrono::duration_cast<std::chrono::microseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count();
    LcmLogWriter log(o.out + "/pipeline_stats.lcmlog");
    log.write(channels::kStats, wall_utime, to_lcm(report, wall_utime, sensor_s));
    log.close();
    std::ofstream(o.out + "/summary.json") << report_to_json(report) << "\n";
    spdlog::info("wrote {0}/summary.json and {0}/pipeline_stats.lcmlog", o.out);
  }
  if (!failures.empty()) {
    std::string all;
    for (const auto& f : failures) all += "\n  - " + f;
    throw CommandError("pipeline-check failed:" + all);
  }
}

}  // namespace

void add_pipeline_check_command(CLI::App& app) {
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "pipeline-check", "Run a synthetic stream through the stage-thread framework and check its guarantees");
  cmd->add_option("--frames", o->frames, "Stereo frames to stream (20 Hz, with 200 Hz IMU)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "x real time; 0 = as fast as possible, blocking and lossless")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--work-ms", o->work_ms, "Simulated tracker cost per frame [ms]")
      ->check(CLI::Range(0.0, 10000.0))
      ->capture_default_str();
  cmd->add_option("--queue", o->queue, "Frame queue capacity")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--out", o->out, "Directory for summary.json and pipeline_stats.lcmlog");
  cmd->callback([o] {
    pipeline::install_interrupt_handler();
    run_check(*o);
  });
}

}  // namespace dynavins::cli
