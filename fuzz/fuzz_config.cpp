// libFuzzer harness: the VINS-Fusion / DynaVINS yaml config loader (EstimatorOptions::load, through
// ConfigReader and OpenCV's FileStorage), with `cam0_calib` / `cam1_calib` resolved next to it: a
// valid pinhole camera file cam_pinhole.yaml sits there. Input: the config file's bytes.
// Contract: the options load, or a std::runtime_error (ConfigError naming file and key) is thrown.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fuzz/fuzz_input_file.hpp"
#include "stages/common/estimator_options.hpp"

namespace {

const char kPinhole[] =
    "%YAML:1.0\n"
    "model_type: PINHOLE\n"
    "camera_name: camera\n"
    "image_width: 752\n"
    "image_height: 480\n"
    "distortion_parameters:\n"
    "   k1: -2.917e-01\n"
    "   k2: 8.228e-02\n"
    "   p1: 5.333e-05\n"
    "   p2: -1.578e-04\n"
    "projection_parameters:\n"
    "   fx: 4.616e+02\n"
    "   fy: 4.603e+02\n"
    "   cx: 3.630e+02\n"
    "   cy: 2.481e+02\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const bool kCameraWritten = [] {
    dynavins::fuzz::write_fuzz_file("config/cam_pinhole.yaml", reinterpret_cast<const uint8_t*>(kPinhole),
                                    sizeof(kPinhole) - 1);
    return true;
  }();
  (void)kCameraWritten;
  const std::string path = dynavins::fuzz::write_fuzz_file("config/config.yaml", data, size);
  try {
    const dynavins::EstimatorOptions options = dynavins::EstimatorOptions::load(path);
    (void)options.print();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
