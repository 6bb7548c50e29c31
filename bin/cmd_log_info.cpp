// `dynavins log-info FILE.lcmlog`: what a recorded log holds, per channel: events, type, rate, span.
// Reads the whole log, so a truncated or corrupt log is reported (file, event, byte) with exit 2: a bad
// event header, a payload of a dynavins_lcm type that does not decode, or a checksum block that does
// not match its events (logs written by dynavins carry them, pipeline/lcm_log.hpp).
#include <cstdio>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include <dynavins_lcm/ground_truth_t.hpp>
#include <dynavins_lcm/image_t.hpp>
#include <dynavins_lcm/imu_t.hpp>
#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/status_t.hpp>
#include <dynavins_lcm/stereo_image_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

#include "bin/commands.hpp"
#include "pipeline/lcm_log.hpp"

namespace dynavins::cli {
namespace {

struct ChannelSummary {
  int64_t events = 0;
  int64_t bytes = 0;
  int64_t first_utime = 0;
  int64_t last_utime = 0;
  int64_t fingerprint = 0;
};

/// A known type: its name and a check that a payload decodes as one (lengths, exact size).
struct KnownType {
  std::string name;
  void (*check)(const pipeline::LcmLogReader& reader, const pipeline::LogRecord& r);
};

template <typename... Msg>
std::map<int64_t, KnownType> known_types() {
  return {{Msg::getHash(),
           KnownType{Msg::getTypeName(),
                     [](const pipeline::LcmLogReader& reader, const pipeline::LogRecord& r) { (void)reader.decode<Msg>(r); }}}...};
}

void run_log_info(const std::string& path) {
  const auto types = known_types<dynavins_lcm::stereo_image_t, dynavins_lcm::imu_t, dynavins_lcm::ground_truth_t,
                                 dynavins_lcm::image_t, dynavins_lcm::pose_t, dynavins_lcm::weighted_feature_set_t,
                                 dynavins_lcm::loop_hypotheses_t, dynavins_lcm::path_t,
                                 dynavins_lcm::pipeline_stats_t, dynavins_lcm::status_t>();
  std::map<std::string, ChannelSummary> channels;
  int64_t total = 0;
  pipeline::LogChecksumStats checksums;
  try {
    pipeline::LcmLogReader reader(path);
    pipeline::LogRecord r;
    while (reader.next(r)) {
      auto& c = channels[r.channel];
      if (c.events == 0) c.first_utime = r.utime, c.fingerprint = pipeline::payload_fingerprint(r.data);
      // Every payload of a known type must decode (a corrupt length is an error naming the event).
      if (const auto t = types.find(pipeline::payload_fingerprint(r.data)); t != types.end()) t->second.check(reader, r);
      ++c.events;
      c.bytes += static_cast<int64_t>(r.data.size());
      c.last_utime = r.utime;
      ++total;
    }
    checksums = reader.checksum_stats();
  } catch (const std::runtime_error& e) {
    throw CommandError(e.what(), 2);
  }
  std::printf("%s: %lld events on %zu channels\n", path.c_str(), static_cast<long long>(total), channels.size());
  std::printf("%-20s %9s %12s %9s %10s  %s\n", "channel", "events", "MB", "rate Hz", "span s", "type");
  for (const auto& [name, c] : channels) {
    const double span = static_cast<double>(c.last_utime - c.first_utime) / 1e6;
    const auto t = types.find(c.fingerprint);
    std::printf("%-20s %9lld %12.3f %9.2f %10.3f  %s\n", name.c_str(), static_cast<long long>(c.events),
                static_cast<double>(c.bytes) / 1e6, span > 0 ? static_cast<double>(c.events - 1) / span : 0.0, span,
                t == types.end() ? "(not a dynavins_lcm type)" : t->second.name.c_str());
  }
  if (checksums.blocks_verified == 0 && checksums.foreign_checksums == 0)
    std::printf("checksums: none (not written by dynavins, e.g. lcm-logger): payloads not verified\n");
  else
    std::printf("checksums: %lld blocks verified (%lld events); %lld events after the last one; %lld checksums of "
                "another log (not checked)\n",
                static_cast<long long>(checksums.blocks_verified), static_cast<long long>(checksums.events_verified),
                static_cast<long long>(checksums.events_unverified), static_cast<long long>(checksums.foreign_checksums));
}

}  // namespace

void add_log_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("log-info", "Summarise an LCM event log: channels, types, rates, time span");
  auto path = std::make_shared<std::string>();
  cmd->add_option("log", *path, "LCM event log (lcm-logger format)")->required()->check(CLI::ExistingFile);
  cmd->callback([path] { run_log_info(*path); });
}

}  // namespace dynavins::cli
