#include "stages/common/camera_loader.hpp"

#include <filesystem>
#include <stdexcept>

#include "stages/common/config_reader.hpp"
#include "stages/common/kannala_brandt_camera.hpp"
#include "stages/common/mei_camera.hpp"
#include "stages/common/pinhole_radtan_camera.hpp"

namespace dynavins {
namespace {

RadtanDistortion read_radtan(const ConfigReader& r) {
  RadtanDistortion d;
  d.k1 = r.get_nested_double("distortion_parameters", "k1");
  d.k2 = r.get_nested_double("distortion_parameters", "k2");
  d.p1 = r.get_nested_double("distortion_parameters", "p1");
  d.p2 = r.get_nested_double("distortion_parameters", "p2");
  return d;
}

}  // namespace

CameraModelPtr load_camera(const std::string& path) {
  const ConfigReader r(path);
  const std::string model = r.get_string("model_type");
  const int width = r.get_int("image_width"), height = r.get_int("image_height");
  try {
    if (model == "PINHOLE") {
      PinholeRadtanCamera::Params p;
      p.width = width;
      p.height = height;
      p.distortion = read_radtan(r);
      p.fx = r.get_nested_double("projection_parameters", "fx");
      p.fy = r.get_nested_double("projection_parameters", "fy");
      p.cx = r.get_nested_double("projection_parameters", "cx");
      p.cy = r.get_nested_double("projection_parameters", "cy");
      return std::make_shared<PinholeRadtanCamera>(p);
    }
    if (model == "MEI") {
      MeiCamera::Params p;
      p.width = width;
      p.height = height;
      p.xi = r.get_nested_double("mirror_parameters", "xi");
      p.distortion = read_radtan(r);
      p.gamma1 = r.get_nested_double("projection_parameters", "gamma1");
      p.gamma2 = r.get_nested_double("projection_parameters", "gamma2");
      p.u0 = r.get_nested_double("projection_parameters", "u0");
      p.v0 = r.get_nested_double("projection_parameters", "v0");
      return std::make_shared<MeiCamera>(p);
    }
    if (model == "KANNALA_BRANDT") {
      KannalaBrandtCamera::Params p;
      p.width = width;
      p.height = height;
      p.k2 = r.get_nested_double("projection_parameters", "k2");
      p.k3 = r.get_nested_double("projection_parameters", "k3");
      p.k4 = r.get_nested_double("projection_parameters", "k4");
      p.k5 = r.get_nested_double("projection_parameters", "k5");
      p.mu = r.get_nested_double("projection_parameters", "mu");
      p.mv = r.get_nested_double("projection_parameters", "mv");
      p.u0 = r.get_nested_double("projection_parameters", "u0");
      p.v0 = r.get_nested_double("projection_parameters", "v0");
      return std::make_shared<KannalaBrandtCamera>(p);
    }
  } catch (const std::invalid_argument& e) {
    throw ConfigError(path, "projection_parameters", e.what());
  }
  r.fail("model_type", "unsupported model '" + model + "' (expected PINHOLE, MEI or KANNALA_BRANDT)");
}

CameraModelPtr load_camera_from_config(const std::string& config_file, const std::string& key,
                                       const std::string& calib, std::string* resolved_path) {
  namespace fs = std::filesystem;
  // VINS-Fusion joins the calib name to the main config's folder; an absolute name stays as is.
  const std::string path = (fs::path(config_file).parent_path() / calib).lexically_normal().string();
  if (resolved_path) *resolved_path = path;
  if (!fs::is_regular_file(path))
    throw ConfigError(config_file, key, "camera calibration file '" + path + "' not found");
  return load_camera(path);
}

}  // namespace dynavins
