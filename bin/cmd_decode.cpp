// `dynavins decode --log FILE [--out DIR] [--channel key=NAME ...]`: reads a recording of DynaVINS'
// outputs (what `lcm-logger` captured of `run --lcm-url` or `live`), decodes every output channel, checks
// what a subscriber relies on (every message decodes, poses finite with unit quaternions, weights in
// [0, 1]) and prints per channel how many arrived and at what rate. With --out it writes the poses as TUM
// files (pose.tum: window poses, pose_imu.tum: IMU-rate poses) that `dynavins eval` and evo read, the
// status changes as status.csv, and the pipeline's health reports over time as stats.csv (one row per
// stage per report) and queues.csv (one row per queue per report), for plots of latency over a long run.
// Exit 1 when a check fails, 2 when the log cannot be read.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/status_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

#include "bin/commands.hpp"
#include "eval/trajectory.hpp"
#include "eval/trajectory_io.hpp"
#include "pipeline/lcm_log.hpp"
#include "pipeline/lcm_publisher.hpp"

namespace dynavins::cli {
namespace {

struct DecodeOptions {
  std::string log;
  std::string out;
  std::vector<std::string> channels;
};

/// What arrived on one channel.
struct ChannelCount {
  int64_t messages = 0;
  int64_t first_utime = 0, last_utime = 0;  ///< the messages' own (sensor) times
  double rate_hz() const {
    return messages > 1 && last_utime > first_utime ? (messages - 1) / ((last_utime - first_utime) * 1e-6) : 0.0;
  }
  void add(int64_t utime) {
    if (messages++ == 0) first_utime = utime;
    last_utime = utime;
  }
};

struct Findings {
  std::vector<std::string> problems;  ///< failed checks, each naming the event
  void fail(const std::string& what) {
    if (problems.size() < 20) problems.push_back(what);
    else if (problems.size() == 20) problems.push_back("... (further problems not listed)");
  }
};

bool finite_pose(const dynavins_lcm::pose_t& m) {
  double qn = 0;
  for (double x : m.orientation) qn += x * x;
  for (double x : m.position)
    if (!std::isfinite(x)) return false;
  return std::isfinite(qn) && std::abs(std::sqrt(qn) - 1.0) < 1e-3;
}

eval::StampedPose stamped(const dynavins_lcm::pose_t& m) {
  const Eigen::Quaterniond q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  return eval::stamped_pose(m.utime * 1000, Eigen::Vector3d(m.position[0], m.position[1], m.position[2]), q);
}

/// Writes a header and rows; the stats' latencies are cumulative since the run started (as published).
void write_csv(const std::string& path, const char* header, const std::vector<std::string>& rows) {
  std::ofstream s(path);
  s << header << "\n";
  for (const auto& row : rows) s << row << "\n";
  if (!s) throw CommandError("cannot write " + path, 2);
}

void run_decode(const DecodeOptions& o) {
  pipeline::PublisherChannels ch;
  try {
    for (const std::string& c : o.channels) ch.set(c);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }
  std::unique_ptr<pipeline::LcmLogReader> reader;
  try {
    reader = std::make_unique<pipeline::LcmLogReader>(o.log);
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);
  }

  std::map<std::string, ChannelCount> counts;
  eval::Trajectory window, imu_rate, corrected;
  window.source = o.log + ":" + ch.pose;
  imu_rate.source = o.log + ":" + ch.pose_imu;
  corrected.source = o.log + ":" + ch.pose_corrected;
  std::vector<std::string> status_rows, stage_rows, queue_rows;
  int64_t features = 0, rejected = 0, other_events = 0;
  float w_min = 1.f, w_max = 0.f;
  Findings f;
  pipeline::LogRecord r;
  try {
    while (reader->next(r)) {
      try {
        if (r.channel == ch.pose || r.channel == ch.pose_imu || r.channel == ch.pose_corrected) {
          const auto m = reader->decode<dynavins_lcm::pose_t>(r);
          counts[r.channel].add(m.utime);
          if (!finite_pose(m)) f.fail(reader->where(r) + ": pose is not finite or its quaternion is not unit");
          (r.channel == ch.pose ? window : r.channel == ch.pose_imu ? imu_rate : corrected).poses.push_back(stamped(m));
        } else if (r.channel == ch.path) {
          const auto m = reader->decode<dynavins_lcm::path_t>(r);
          counts[r.channel].add(m.utime);
          for (const auto& p : m.poses)
            if (!finite_pose(p)) f.fail(reader->where(r) + ": a path pose is not finite");
        } else if (r.channel == ch.loops) {
          const auto m = reader->decode<dynavins_lcm::loop_hypotheses_t>(r);
          counts[r.channel].add(m.utime);
          for (const auto& h : m.hypotheses)
            if (!(h.weight >= 0.f && h.weight <= 1.f))
              f.fail(fmt::format("{}: hypothesis weight {} outside [0, 1]", reader->where(r), h.weight));
        } else if (r.channel == ch.features) {
          const auto m = reader->decode<dynavins_lcm::weighted_feature_set_t>(r);
          counts[r.channel].add(m.utime);
          for (const auto& x : m.features) {
            ++features;
            rejected += x.weight < 0.5f;
            w_min = std::min(w_min, x.weight), w_max = std::max(w_max, x.weight);
            if (!(x.weight >= 0.f && x.weight <= 1.f))
              f.fail(fmt::format("{}: feature {} has weight {} outside [0, 1]", reader->where(r), x.id, x.weight));
          }
        } else if (r.channel == ch.status) {
          const auto m = reader->decode<dynavins_lcm::status_t>(r);
          counts[r.channel].add(m.utime);
          if (m.status < 0 || m.status > dynavins_lcm::status_t::RESET)
            f.fail(fmt::format("{}: unknown status {}", reader->where(r), m.status));
          status_rows.push_back(fmt::format("{},{},{},{},\"{}\"", m.utime, int(m.status), m.frames, m.resets, m.reason));
        } else if (r.channel == ch.stats) {
          const auto m = reader->decode<dynavins_lcm::pipeline_stats_t>(r);
          counts[r.channel].add(r.utime);  // stats carry wall-clock time
          if (m.num_stages == 0) f.fail(reader->where(r) + ": stats message lists no stage");
          for (const auto& st : m.stages)
            stage_rows.push_back(fmt::format("{:.3f},{:.4f},{},{},{},{},{},{},{}", m.wall_s, m.realtime_factor, st.name,
                                             st.processed, st.process_ms_mean, st.process_ms_p95, st.process_ms_max,
                                             st.wait_ms_mean, st.wait_ms_p95));
          for (const auto& q : m.queues)
            queue_rows.push_back(fmt::format("{:.3f},{},{},{},{},{},{},{}", m.wall_s, q.name, q.capacity, q.depth,
                                             q.max_depth, q.pushed, q.delivered, q.dropped));
        } else {
          ++other_events;
        }
      } catch (const std::runtime_error& e) {
        f.fail(e.what());  // a payload that is not its channel's type
      }
    }
  } catch (const std::exception& e) {
    throw CommandError(e.what(), 2);  // truncated or corrupt log
  }

  std::printf("%-24s %-10s %10s %10s\n", "channel", "key", "messages", "rate [Hz]");
  for (const auto& [key, name] : ch.list()) {
    const ChannelCount c = counts.count(name) ? counts[name] : ChannelCount{};
    std::printf("%-24s %-10s %10lld %10.1f\n", name.c_str(), key.c_str(), static_cast<long long>(c.messages),
                c.rate_hz());
  }
  std::printf("features                %lld in all, weights in [%.3f, %.3f], %.1f %% below 0.5\n",
              static_cast<long long>(features), features ? w_min : 0.f, features ? w_max : 0.f,
              features ? 100.0 * rejected / features : 0.0);
  if (other_events) std::printf("other channels          %lld events (not DynaVINS outputs)\n", static_cast<long long>(other_events));

  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    eval::write_tum(o.out + "/pose.tum", window);
    eval::write_tum(o.out + "/pose_imu.tum", imu_rate);
    if (!corrected.empty()) eval::write_tum(o.out + "/pose_corrected.tum", corrected);
    write_csv(o.out + "/status.csv", "utime,status,frames,resets,reason", status_rows);
    write_csv(o.out + "/stats.csv",
              "wall_s,realtime_factor,stage,processed,process_ms_mean,process_ms_p95,process_ms_max,wait_ms_mean,"
              "wait_ms_p95",
              stage_rows);
    write_csv(o.out + "/queues.csv", "wall_s,queue,capacity,depth,max_depth,pushed,delivered,dropped", queue_rows);
    std::printf("outputs                 %s/pose.tum, pose_imu.tum, status.csv, stats.csv, queues.csv\n",
                o.out.c_str());
  }
  if (!f.problems.empty()) {
    for (const auto& p : f.problems) std::fprintf(stderr, "decode: %s\n", p.c_str());
    throw CommandError(fmt::format("{}: {} check(s) failed", o.log, f.problems.size()), 1);
  }
}

}  // namespace

void add_decode_command(CLI::App& app) {
  auto o = std::make_shared<DecodeOptions>();
  auto* cmd = app.add_subcommand(
      "decode", "Decode a recording of DynaVINS' LCM outputs (lcm-logger): check it, count channels, write poses as TUM");
  cmd->add_option("--log", o->log, "LCM log recorded with lcm-logger")->required();
  cmd->add_option("--out", o->out, "Write pose.tum, pose_imu.tum, status.csv, stats.csv and queues.csv here");
  cmd->add_option("--channel", o->channels, "Output channel name as given to run/live: --channel key=NAME");
  cmd->callback([o] { run_decode(*o); });
}

}  // namespace dynavins::cli
