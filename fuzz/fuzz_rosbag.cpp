// libFuzzer harness: the ROS 1 bag import (io/rosbag: our bounds-checked walk of the bag's records,
// then Debian's rosbag_storage reading it, message deserialisation, image conversion, stereo
// pairing, stamp checks). Input: the bytes of a .bag file, read with VIODE's topic names.
// Contract: every message is read, or a std::runtime_error (io::InputError naming the file, and the
// topic and message or the byte offset) is thrown.

#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz/fuzz_input_file.hpp"
#include "io/rosbag/rosbag_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = dynavins::fuzz::write_fuzz_file("input.bag", data, size);
  try {
    dynavins::io::RosbagReader reader(path);
    dynavins::SensorEvent event;
    while (reader.next(event)) {
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
