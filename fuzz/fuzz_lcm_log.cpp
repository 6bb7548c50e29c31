// libFuzzer harness: the LCM event-log reader and the sensor-log source on top of it (sync word,
// header lengths, payload decode of stereo_image_t / imu_t / ground_truth_t / image_t, image
// conversion, per-channel time checks, reorder window). Input: the bytes of a log file.
// Contract under test: every input either reads to its end or throws a std::runtime_error (the
// readers' documented error, naming file and event); anything else (a crash, a sanitizer report,
// another exception type) is a finding.

#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz/fuzz_input_file.hpp"
#include "pipeline/sensor_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = dynavins::fuzz::write_fuzz_file("input.lcmlog", data, size);
  try {
    // The raw event reader alone (what log-info walks).
    dynavins::pipeline::LcmLogReader reader(path);
    dynavins::pipeline::LogRecord record;
    while (reader.next(record)) {
    }
  } catch (const std::runtime_error&) {
  }
  try {
    dynavins::pipeline::LcmLogSource source(path);
    dynavins::SensorEvent event;
    while (source.next(event)) {
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
