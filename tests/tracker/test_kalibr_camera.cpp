// Loading the EuRoC clip's own Kalibr calibration.
#include <filesystem>
#include <fstream>

#include <catch2/catch.hpp>

#include "stages/common/config_error.hpp"
#include "stages/tracker/kalibr_camera.hpp"

using namespace dynavins;
using namespace dynavins::tracker;

TEST_CASE("load_kalibr_camera: EuRoC cam0 intrinsics, distortion and T_BS", "[tracker][kalibr]") {
  const auto c = load_kalibr_camera(std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro/mav0/cam0/sensor.yaml");
  const auto& p = c.camera->params();
  CHECK(p.width == 752);
  CHECK(p.height == 480);
  CHECK(p.fx == Approx(458.654));
  CHECK(p.cy == Approx(248.375));
  CHECK(p.distortion.k1 == Approx(-0.28340811));
  CHECK(p.distortion.p2 == Approx(1.76187114e-05));
  CHECK(c.T_body_cam.translation().x() == Approx(-0.0216401454975));
  CHECK(c.T_body_cam(1, 0) == Approx(0.999557249008));
  // A calibration's rotation is orthonormal: the file was read row by row, not column by column.
  CHECK((c.T_body_cam.linear() * c.T_body_cam.linear().transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6);
}

TEST_CASE("load_kalibr_camera: a missing file or another model is a ConfigError", "[tracker][kalibr]") {
  CHECK_THROWS_AS(load_kalibr_camera("/nonexistent/sensor.yaml"), ConfigError);
  const auto path = std::filesystem::temp_directory_path() / "dynavins_kalibr_equi.yaml";
  std::ofstream(path) << "%YAML:1.0\ncamera_model: pinhole\ndistortion_model: equidistant\n";
  CHECK_THROWS_AS(load_kalibr_camera(path.string()), ConfigError);
}
