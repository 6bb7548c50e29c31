// LCM event logs: written with LCM's own LogFile, read back by our reader and by LCM's.
#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>

#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_log.hpp"
#include "pipeline/sensor_log.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;
namespace fs = std::filesystem;

namespace {

fs::path temp_log(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "dynavins_test_lcm_log";
  fs::create_directories(dir);
  return dir / name;
}

/// Writes 20 IMU samples and 2 stereo frames, interleaved in time.
void write_sample_log(const fs::path& path) {
  LcmLogWriter w(path.string());
  for (int i = 0; i < 20; ++i) {
    ImuSample s;
    s.t_ns = i * 5'000'000LL;
    s.acc = {0, 0, 9.81 + i};
    w.write(channels::kImu, ns_to_utime(s.t_ns), to_lcm(s));
    if (i % 10 == 0) {
      StereoFrame f;
      f.t_ns = s.t_ns;
      f.seq = i / 10;
      f.left = cv::Mat(30, 40, CV_8UC1, cv::Scalar(i));
      f.right = f.left.clone();
      w.write(channels::kStereo, ns_to_utime(f.t_ns), to_lcm(f, ImageEncoding::Png));
    }
  }
  CHECK(w.events_written() == 22);
  w.close();
}

}  // namespace

TEST_CASE("LCM log: written, then read back event by event", "[lcm][log]") {
  const auto path = temp_log("roundtrip.lcmlog");
  write_sample_log(path);

  LcmLogReader reader(path.string());
  LogRecord r;
  int imu = 0, stereo = 0;
  while (reader.next(r)) {
    if (r.channel == channels::kImu) {
      const ImuSample s = from_lcm(reader.decode<dynavins_lcm::imu_t>(r));
      CHECK(s.t_ns == imu * 5'000'000LL);
      CHECK(s.acc.z() == 9.81 + imu);
      ++imu;
    } else {
      REQUIRE(r.channel == channels::kStereo);
      const StereoFrame f = from_lcm(reader.decode<dynavins_lcm::stereo_image_t>(r));
      CHECK(f.seq == stereo);
      CHECK(f.left.at<uint8_t>(0, 0) == stereo * 10);
      ++stereo;
    }
  }
  CHECK(imu == 20);
  CHECK(stereo == 2);
  CHECK(reader.position() == reader.file_size());

  // The 22 events are one checksum block, verified.
  CHECK(reader.checksum_stats().blocks_verified == 1);
  CHECK(reader.checksum_stats().events_verified == 22);
  CHECK(reader.checksum_stats().events_unverified == 0);

  // LCM's own reader sees the same events, and the block's checksum event after them: the file is a
  // standard lcm-logger log.
  lcm::LogFile lcm_log(path.string(), "r");
  REQUIRE(lcm_log.good());
  int n = 0;
  std::string last_channel;
  while (const lcm::LogEvent* ev = lcm_log.readNextEvent()) ++n, last_channel = ev->channel;
  CHECK(n == 22 + 1);
  CHECK(last_channel == kChecksumChannel);
}

TEST_CASE("LCM log: a truncated log is an error naming the file, event and byte", "[lcm][log]") {
  const auto path = temp_log("truncated.lcmlog");
  write_sample_log(path);
  // Cut into the last data event: past the closing checksum event (header, channel, 20 bytes) and 7 more.
  const auto checksum_event_bytes = 28 + std::string(kChecksumChannel).size() + 20;
  fs::resize_file(path, fs::file_size(path) - checksum_event_bytes - 7);
  LcmLogReader reader(path.string());
  LogRecord r;
  int read = 0;
  try {
    while (reader.next(r)) ++read;
    FAIL("a truncated log was read to the end without an error");
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    CHECK_THAT(msg, Catch::Contains(path.string()));
    CHECK_THAT(msg, Catch::Contains("event 21"));
    CHECK_THAT(msg, Catch::Contains("truncated"));
  }
  CHECK(read == 21);
}

TEST_CASE("LCM log: an event claiming 0x7fffffff data bytes is reported with its true size", "[lcm][log]") {
  const auto path = temp_log("huge_length.lcmlog");
  write_sample_log(path);
  {  // the first event's data length field (bytes 24..27 of its header) set to 0x7fffffff
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(24);
    const char len[4] = {0x7f, static_cast<char>(0xff), static_cast<char>(0xff), static_cast<char>(0xff)};
    f.write(len, 4);
  }
  LcmLogReader reader(path.string());
  LogRecord r;
  try {
    reader.next(r);
    FAIL("an event longer than the file was read");
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    CHECK_THAT(msg, Catch::Contains("truncated"));
    CHECK_THAT(msg, !Catch::Contains("needs -"));  // no overflowed, negative size
    CHECK_THAT(msg, Catch::Contains("needs 21474836"));
  }
}

TEST_CASE("LCM log: garbage and wrong payload types are errors, a missing file too", "[lcm][log]") {
  const auto path = temp_log("garbage.lcmlog");
  std::ofstream(path) << "this is not an LCM log, but long enough to hold a header";
  LcmLogReader garbage(path.string());
  LogRecord r;
  CHECK_THROWS_WITH(garbage.next(r), Catch::Contains("bad sync word"));

  const auto good = temp_log("types.lcmlog");
  write_sample_log(good);
  LcmLogReader reader(good.string());
  REQUIRE(reader.next(r));
  REQUIRE(r.channel == channels::kImu);
  CHECK_THROWS_WITH(reader.decode<dynavins_lcm::stereo_image_t>(r),
                    Catch::Contains("channel IMU") && Catch::Contains("stereo_image_t"));

  CHECK_THROWS_WITH(LcmLogReader("/nonexistent/x.lcmlog"), Catch::Contains("/nonexistent/x.lcmlog"));
}

namespace {

/// A log of `frames` raw (gray8) 752x480 stereo frames, as `convert --encoding gray8` writes them.
void write_raw_image_log(const fs::path& path, int frames) {
  LcmLogWriter w(path.string());
  for (int i = 0; i < frames; ++i) {
    StereoFrame f;
    f.t_ns = 1'000'000'000LL + i * 50'000'000LL;
    f.seq = i;
    f.left = cv::Mat(480, 752, CV_8UC1);
    cv::randu(f.left, 0, 255);
    f.right = f.left.clone();
    w.write(channels::kStereo, ns_to_utime(f.t_ns), to_lcm(f, ImageEncoding::Gray8));
  }
}

/// Every data event of `path`; rethrows the reader's error.
int read_all(const fs::path& path, LogChecksumStats* stats = nullptr) {
  LcmLogReader reader(path.string());
  LogRecord r;
  int n = 0;
  while (reader.next(r)) {
    (void)reader.decode<dynavins_lcm::stereo_image_t>(r);
    ++n;
  }
  if (stats) *stats = reader.checksum_stats();
  return n;
}

}  // namespace

TEST_CASE("LCM log: raw image pixels overwritten on disk are a checksum error naming the events and bytes",
          "[lcm][log]") {
  // 20 frames of 722 kB: checksum blocks of 4 MiB hold 6 frames each, so the log has 4 blocks.
  const auto path = temp_log("raw_overwritten.lcmlog");
  write_raw_image_log(path, 20);
  LogChecksumStats clean;
  REQUIRE(read_all(path, &clean) == 20);
  CHECK(clean.blocks_verified == 4);
  CHECK(clean.events_verified == 20);

  // 3 kB overwritten inside frame 9's left pixels: every length field stays intact, so it decodes.
  const int64_t frame_bytes = 28 + static_cast<int64_t>(std::string(channels::kStereo).size()) +
                              static_cast<int64_t>(to_lcm(StereoFrame{}, ImageEncoding::Gray8).getEncodedSize()) +
                              2 * 480 * 752;
  const int64_t block_event_bytes = 28 + static_cast<int64_t>(std::string(kChecksumChannel).size()) + 20;
  const int64_t at = 9 * frame_bytes + 1 * block_event_bytes + 20'000;  // frame 9 is in the second block
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(at);
    const std::string junk(3000, '\x5a');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  }
  try {
    read_all(path);
    FAIL("an overwritten log was read without an error");
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    INFO(msg);
    CHECK_THAT(msg, Catch::Contains(path.string()));
    CHECK_THAT(msg, Catch::Contains("checksum mismatch"));
    // The second block: data events #7 to #12 (file events, the first block's checksum is #6), and its bytes.
    CHECK_THAT(msg, Catch::Contains("events #7 to #12"));
    const int64_t block_begin = 6 * frame_bytes + block_event_bytes;
    CHECK_THAT(msg, Catch::Contains("bytes " + std::to_string(block_begin) + " to "));
    CHECK(at >= block_begin);
    CHECK(at + 3000 <= block_begin + 6 * frame_bytes);
  }

  // The sensor-log source (what `run --log` reads) stops with that error too.
  LcmLogSource source(path.string());
  SensorEvent ev;
  CHECK_THROWS_WITH(
      [&] {
        while (source.next(ev)) {
        }
      }(),
      Catch::Contains("checksum mismatch"));
}

TEST_CASE("LCM log: a log without checksums (lcm-logger) reads unverified; a foreign checksum is not an error",
          "[lcm][log]") {
  const auto path = temp_log("no_checksums.lcmlog");
  {
    lcm::LogFile log(path.string(), "w");
    ImuSample s;
    const auto msg = to_lcm(s);
    std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
    msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
    lcm::LogEvent ev;
    ev.channel = channels::kImu;
    ev.datalen = static_cast<int32_t>(buf.size());
    ev.data = buf.data();
    for (int i = 0; i < 5; ++i) {
      ev.eventnum = ev.timestamp = i;
      REQUIRE(log.writeEvent(&ev) == 0);
    }
    // A checksum event of another log (re-recorded from lcm-logplayer): its block does not line up.
    std::vector<uint8_t> other(20, 0);
    other[7] = 99;  // block offset 99
    other[15] = 5;  // 5 events
    ev.channel = kChecksumChannel;
    ev.datalen = 20;
    ev.data = other.data();
    REQUIRE(log.writeEvent(&ev) == 0);
  }
  LcmLogReader reader(path.string());
  LogRecord r;
  int n = 0;
  while (reader.next(r)) ++n;
  CHECK(n == 5);
  CHECK(reader.checksum_stats().blocks_verified == 0);
  CHECK(reader.checksum_stats().foreign_checksums == 1);
  CHECK(reader.checksum_stats().events_unverified == 5);
}
