// LCM event logs: written with LCM's own LogFile, read back by our reader and by LCM's.
#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>

#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/lcm_log.hpp"

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

  // LCM's own reader sees the same events: the file is a standard lcm-logger log.
  lcm::LogFile lcm_log(path.string(), "r");
  REQUIRE(lcm_log.good());
  int n = 0;
  while (lcm_log.readNextEvent()) ++n;
  CHECK(n == 22);
}

TEST_CASE("LCM log: a truncated log is an error naming the file, event and byte", "[lcm][log]") {
  const auto path = temp_log("truncated.lcmlog");
  write_sample_log(path);
  fs::resize_file(path, fs::file_size(path) - 7);
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
