// libFuzzer harness: the camodocs camera calibration loader (load_camera: PINHOLE, MEI,
// KANNALA_BRANDT) and the model it builds (a projection and a back-projection of the image centre).
// Input: the camera yaml's bytes.
// Contract: a camera loads, or a std::runtime_error (ConfigError naming file and key) is thrown.

#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz/fuzz_input_file.hpp"
#include "stages/common/camera_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string path = dynavins::fuzz::write_fuzz_file("camera.yaml", data, size);
  try {
    const dynavins::CameraModelPtr camera = dynavins::load_camera(path);
    (void)camera->describe();
    const Eigen::Vector3d ray = camera->lift(Eigen::Vector2d(camera->width() / 2.0, camera->height() / 2.0));
    (void)camera->project(ray);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
