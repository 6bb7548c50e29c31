// EstimatorOptions: real VINS-Fusion and DynaVINS configs load unchanged, the DynaVINS lambda
// mapping, the sim's own configs, and errors that name the key and the file.

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "io/vins_config_writer.hpp"
#include "stages/common/config_error.hpp"
#include "stages/common/estimator_options.hpp"

using namespace dynavins;
namespace fs = std::filesystem;

namespace {

const std::string kEuroc = std::string(DYNAVINS_SHARED_DIR) + "/data/vins_fusion_euroc_config/";
const std::string kViode = std::string(DYNAVINS_SHARED_DIR) + "/data/dynavins_viode_config/";

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A scratch copy of a shared config folder whose main file can be edited per test.
struct ScratchConfig {
  fs::path dir;
  explicit ScratchConfig(const std::string& from) {
    static int n = 0;
    dir = fs::temp_directory_path() / ("dynavins_cfg_" + std::to_string(::getpid()) + "_" + std::to_string(n++));
    fs::remove_all(dir);
    fs::create_directories(dir);
    for (const auto& e : fs::directory_iterator(from)) fs::copy_file(e.path(), dir / e.path().filename());
  }
  ~ScratchConfig() { fs::remove_all(dir); }
  // Writes `name` as the file `base` with `pattern` replaced by `replacement` (must match).
  std::string edit(const std::string& base, const std::string& pattern, const std::string& replacement) {
    const std::string text = slurp((dir / base).string());
    const std::string out = std::regex_replace(text, std::regex(pattern), replacement);
    REQUIRE(out != text);
    const std::string path = (dir / ("edited_" + base)).string();
    std::ofstream(path) << out;
    return path;
  }
};

}  // namespace

TEST_CASE("VINS-Fusion's EuRoC stereo-imu config (MEI cameras) loads unchanged", "[options]") {
  const auto o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  CHECK(o.use_imu);
  REQUIRE(o.num_of_cam == 2);
  REQUIRE(o.cameras.size() == 2);
  CHECK(o.cameras[0]->name() == "MEI");
  CHECK(o.cameras[1]->name() == "MEI");
  CHECK(o.camera_files[0] == fs::path(kEuroc + "cam0_mei.yaml").lexically_normal().string());
  CHECK(o.image_width == 752);
  CHECK(o.image_height == 480);
  CHECK(o.body_T_cam[0].translation().isApprox(Eigen::Vector3d(-0.0216401454975, -0.064676986768, 0.00981073058949)));
  CHECK(o.body_T_cam[1](0, 3) == Approx(-0.0198435579556));
  CHECK(o.body_T_cam[1](1, 0) == Approx(0.999598781151).epsilon(1e-5));
  CHECK(o.max_cnt == 150);
  CHECK(o.min_dist == 30);
  CHECK(o.freq == 10);
  CHECK(o.F_threshold == 1.0);
  CHECK(o.show_track);
  CHECK(o.flow_back);
  CHECK(o.max_solver_time == 0.04);
  CHECK(o.max_num_iterations == 8);
  CHECK(o.keyframe_parallax == 10.0);
  CHECK(o.acc_n == 0.1);
  CHECK(o.gyr_n == 0.01);
  CHECK(o.acc_w == 0.001);
  CHECK(o.gyr_w == 0.0001);
  CHECK(o.g_norm == 9.81007);
  CHECK_FALSE(o.estimate_td);
  CHECK(o.td == 0.0);
  CHECK(o.estimate_extrinsic == 0);
  // No DynaVINS keys: the paper's defaults.
  CHECK(o.lambda_w == 1.0);
  CHECK(o.lambda_m == 0.2);
  CHECK(o.alternating_converge == 0.9);
  CHECK(o.margin_feature_thresh == 0.1);
  CHECK(o.window_size == 10);
  CHECK(o.keys_from_file.count("regularization_lambda") == 0);
}

TEST_CASE("VINS-Fusion's EuRoC mono-imu config loads only cam0", "[options]") {
  const auto o = EstimatorOptions::load(kEuroc + "euroc_mono_imu_config.yaml");
  CHECK(o.use_imu);
  CHECK(o.num_of_cam == 1);
  CHECK(o.cameras.size() == 1);
  CHECK(o.body_T_cam.size() == 1);
  CHECK(o.cameras[0]->name() == "MEI");
}

TEST_CASE("VINS-Fusion's EuRoC stereo config without IMU loads with no IMU keys", "[options]") {
  const auto o = EstimatorOptions::load(kEuroc + "euroc_stereo_config.yaml");
  CHECK_FALSE(o.use_imu);
  CHECK(o.num_of_cam == 2);
  CHECK(o.keys_from_file.count("acc_n") == 0);
  CHECK(o.print().find("acc_n") == std::string::npos);
}

TEST_CASE("A user's EuRoC config switched to the pinhole camera files loads", "[options]") {
  ScratchConfig s(kEuroc);
  const std::string path = s.edit("euroc_stereo_imu_config.yaml", "_mei\\.yaml", "_pinhole.yaml");
  const auto o = EstimatorOptions::load(path);
  CHECK(o.cameras[0]->name() == "PINHOLE");
  CHECK(o.cameras[1]->name() == "PINHOLE");
}

TEST_CASE("The authors' DynaVINS VIODE configs load with their keys", "[options][dynavins]") {
  for (const char* file : {"calibration_stereo.yaml", "calibration_mono.yaml"}) {
    INFO(file);
    const auto o = EstimatorOptions::load(kViode + file);
    // "num_of_cam:1" (no space) is read by OpenCV as the key num_of_cam, as the authors relied on.
    CHECK(o.num_of_cam == (std::string(file) == "calibration_stereo.yaml" ? 2 : 1));
    CHECK(o.cameras[0]->name() == "PINHOLE");
    CHECK(o.cameras[0]->lift_normalized({376.0 + 37.6, 240.0}).isApprox(Eigen::Vector2d(0.1, 0.0)));
    CHECK(o.min_dist == 15);
    CHECK(o.F_threshold == 2.0);
    CHECK(o.max_solver_time == 0.3);
    CHECK(o.max_num_iterations == 10);
    CHECK(o.gyr_w == 4.0e-5);
    // "dyna_on:   true # do not change it to false": OpenCV keeps the comment inside the string.
    CHECK(o.dyna_on);
    CHECK(o.momentum_on);
    CHECK(o.regularization_gamma == 2.0);
    CHECK(o.lambda_m == 0.2);
    CHECK(o.alternating_converge == 0.9);
    CHECK(o.margin_feature_thresh == 0.1);
    CHECK(o.keys_from_file.count("regularization_lambda") == 1);
    if (o.num_of_cam == 2) CHECK(o.body_T_cam[1].translation().isApprox(Eigen::Vector3d(0, 0.05, 0)));
  }
}

TEST_CASE("regularization_lambda is the authors' gamma: lambda_w = gamma^2", "[options][dynavins]") {
  CHECK(EstimatorOptions::load(kViode + "calibration_stereo.yaml").lambda_w == 4.0);
  ScratchConfig s(kViode);
  CHECK(EstimatorOptions::load(s.edit("calibration_stereo.yaml", "regularization_lambda:  2.0",
                                      "regularization_lambda: 0.5"))
            .lambda_w == 0.25);
  const auto absent = EstimatorOptions::load(s.edit("calibration_stereo.yaml", "regularization_lambda:  2.0\n", ""));
  CHECK(absent.regularization_gamma == 1.0);
  CHECK(absent.lambda_w == 1.0);  // the paper's default
}

TEST_CASE("print() lists every effective option with its source", "[options]") {
  const auto o = EstimatorOptions::load(kViode + "calibration_stereo.yaml");
  const std::string p = o.print();
  for (const char* key : {"imu", "num_of_cam", "cam0_calib", "cam1_calib", "body_T_cam0", "body_T_cam1", "image_width",
                          "image_height", "max_cnt", "min_dist", "freq", "F_threshold", "flow_back", "patch_refine", "show_track",
                          "max_solver_time", "max_num_iterations", "keyframe_parallax", "acc_n", "gyr_n", "acc_w",
                          "gyr_w", "g_norm", "estimate_td", "td", "estimate_extrinsic", "regularization_lambda",
                          "lambda_w", "momentum_lambda", "alternating_converge", "margin_feature_thresh",
                          "weighted_huber", "window_size"})
    CHECK_THAT(p, Catch::Contains(std::string("  ") + key + " "));
  CHECK_THAT(p, Catch::Contains("PINHOLE 752x480 fx=376"));
  CHECK(std::regex_search(p, std::regex("max_cnt +=  ?150 +\\(file\\)")));
  CHECK(std::regex_search(p, std::regex("window_size +=  ?10 +\\(default\\)")));
  CHECK(std::regex_search(p, std::regex("lambda_w +=  ?4 +\\(derived\\)")));
}

TEST_CASE("The sim's own VINS-Fusion-format config loads", "[options][sim]") {
  const fs::path dir = fs::temp_directory_path() / ("dynavins_sim_cfg_" + std::to_string(::getpid()));
  io::VinsStereoConfig c;
  c.cam0 = {640, 480, 400, 401, 320, 240, -0.1, 0.01, 1e-4, -1e-4};
  c.cam1 = c.cam0;
  c.body_T_cam1.translation() = Eigen::Vector3d(0.11, 0, 0);
  c.acc_n = 0.08;
  io::write_vins_stereo_config(dir.string(), c);
  const auto o = EstimatorOptions::load((dir / "vins_config.yaml").string());
  CHECK(o.num_of_cam == 2);
  CHECK(o.image_width == 640);
  CHECK(o.acc_n == Approx(0.08));
  CHECK(o.body_T_cam[1].translation().isApprox(Eigen::Vector3d(0.11, 0, 0)));
  CHECK(o.cameras[1]->project({0.0, 0.0, 1.0}).isApprox(Eigen::Vector2d(320, 240)));
  fs::remove_all(dir);
}

TEST_CASE("Errors name the key and the file", "[options][errors]") {
  ScratchConfig s(kEuroc);
  const std::string base = "euroc_stereo_imu_config.yaml";

  SECTION("missing required key") {
    const std::string path = s.edit(base, "\nacc_n: 0.1", "\n");
    CHECK_THROWS_AS(EstimatorOptions::load(path), ConfigError);
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("'acc_n'") &&
                                                        Catch::Contains("missing"));
  }
  SECTION("wrongly typed value") {
    const std::string path = s.edit(base, "max_cnt: 150", "max_cnt: \"many\"");
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("'max_cnt'") &&
                                                        Catch::Contains("integer") && Catch::Contains("many"));
  }
  SECTION("non-integral real for an integer key") {
    const std::string path = s.edit(base, "max_num_iterations: 8", "max_num_iterations: 8.5");
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains("'max_num_iterations'"));
  }
  SECTION("extrinsic that is not a matrix") {
    const std::string path = s.edit(base, "body_T_cam1: !!opencv-matrix", "body_T_cam1: 3\nunused: !!opencv-matrix");
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("'body_T_cam1'"));
  }
  SECTION("missing camera calibration file") {
    const std::string path = s.edit(base, "cam1_mei.yaml", "cam1_missing.yaml");
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("'cam1_calib'") &&
                                                        Catch::Contains("cam1_missing.yaml"));
  }
  SECTION("bad key inside the camera file names the camera file") {
    const std::string cam = s.edit("cam0_mei.yaml", "   xi:", "   chi:");
    const std::string path = s.edit(base, "cam0_mei.yaml", fs::path(cam).filename().string());
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(cam) && Catch::Contains("mirror_parameters.xi"));
  }
  SECTION("num_of_cam out of range") {
    const std::string path = s.edit(base, "num_of_cam: 2", "num_of_cam: 3");
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains("'num_of_cam'"));
  }
  SECTION("missing config file") {
    CHECK_THROWS_WITH(EstimatorOptions::load((s.dir / "nope.yaml").string()),
                      Catch::Contains("nope.yaml") && Catch::Contains("not found"));
  }
}
