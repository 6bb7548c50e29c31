// EstimatorOptions: real VINS-Fusion and DynaVINS configs load unchanged, the DynaVINS lambda
// mapping, the sim's own configs, errors that name the key and the file, and the option table (every
// key through the yaml and --set, ranges, NaN, duplicate and unknown keys, the README's table).

#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <spdlog/spdlog.h>

#include "io/vins_config_writer.hpp"
#include "stages/common/config_error.hpp"
#include "stages/common/config_reader.hpp"
#include "stages/common/estimator_options.hpp"
#include "stages/tracker/tracker_options.hpp"
#include "tests/log_capture.hpp"

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

TEST_CASE("VINS-Mono's equalize key turns on the tracker's CLAHE", "[options]") {
  ScratchConfig s(kViode);
  const auto absent = EstimatorOptions::load(kViode + "calibration_stereo.yaml");
  CHECK_FALSE(absent.equalize);
  CHECK_FALSE(tracker::TrackerOptions::from(absent).clahe);
  const auto on = EstimatorOptions::load(
      s.edit("calibration_stereo.yaml", "regularization_lambda:  2.0\n", "regularization_lambda:  2.0\nequalize: 1\n"));
  CHECK(on.equalize);
  CHECK(tracker::TrackerOptions::from(on).clahe);
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
  CHECK(o.unknown_keys.empty());
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
  SECTION("an extrinsic matrix of the wrong size is rejected by its header, before OpenCV allocates it") {
    // Found by fuzz_config: a garbled `rows` made OpenCV ask for a 64 GB matrix.
    const std::string path = s.edit(base, "body_T_cam1: !!opencv-matrix\n   rows: 4", "body_T_cam1: !!opencv-matrix\n   rows: 400000");
    CHECK_THROWS_WITH(EstimatorOptions::load(path),
                      Catch::Contains(path) && Catch::Contains("'body_T_cam1'") && Catch::Contains("rows: 400000"));
  }
  SECTION("an empty key is refused, naming file and line, before OpenCV reads out of bounds on it") {
    // Found by fuzz_camera (tests/data/fuzz_regressions/camera/): std::length_error out of FileStorage::open
    // in Release, a SEGV inside OpenCV under ThreadSanitizer.
    const std::string cam = (fs::path(DYNAVINS_SOURCE_DIR) / "tests/data/fuzz_regressions/camera/opencv_parser_length_error.yaml").string();
    CHECK_THROWS_AS(ConfigReader(cam), ConfigError);
    CHECK_THROWS_WITH(ConfigReader(cam), Catch::Contains(cam) && Catch::Contains("line 12: a key is missing"));
  }
  SECTION("a second %YAML directive or junk after ---: refused, naming file and line, before OpenCV loops on it") {
    // Found by fuzz_camera (tests/data/fuzz_regressions/camera/): FileStorage::open never returned.
    const std::string cam =
        (fs::path(DYNAVINS_SOURCE_DIR) / "tests/data/fuzz_regressions/camera/opencv_parser_hang_second_directive.yaml")
            .string();
    CHECK_THROWS_WITH(ConfigReader(cam), Catch::Contains(cam) && Catch::Contains("line 2: a %YAML directive"));
    const std::string path = (s.dir / "late_directive.yaml").string();
    std::ofstream(path) << "# a comment first\n%YAML:1.0\nimage_width: 752\n";
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("line 2"));
    const std::string junk =
        (fs::path(DYNAVINS_SOURCE_DIR) / "tests/data/fuzz_regressions/camera/opencv_parser_hang_junk_after_marker.yaml")
            .string();
    CHECK_THROWS_WITH(ConfigReader(junk), Catch::Contains(junk) && Catch::Contains("line 2: the document marker ---"));
  }
  SECTION("a yaml whose top level is a sequence names the file (OpenCV asserted in its key lookup)") {
    const std::string path = (s.dir / "sequence.yaml").string();
    std::ofstream(path) << "%YAML:1.0\n- 1\n- 2\n";
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("not a map of keys"));
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

// ---- The option table: every key loads, overrides, range-checks and is documented the same way. ----

namespace {

// Text of `x` that reads back exactly.
template <typename T>
std::string exact(T x) {
  std::ostringstream s;
  s << std::setprecision(17) << std::boolalpha << x;
  return s.str();
}

// A value of the key other than its default, inside its range, as yaml / --set text.
std::string other_value(const OptionSpec& s) {
  return std::visit(
      [&](auto m) -> std::string {
        const auto d = EstimatorOptions{}.*m;
        using T = std::remove_const_t<decltype(d)>;
        if constexpr (std::is_same_v<T, bool>) {
          return d ? "false" : "true";
        } else if constexpr (std::is_same_v<T, int>) {
          return std::to_string(d + 1 <= s.range.hi ? d + 1 : d - 1);
        } else {
          return exact(d < s.range.hi ? (d + s.range.hi) / 2 : (s.range.lo + d) / 2);
        }
      },
      s.field);
}

// Values of the key outside its range (flags: not a flag at all).
std::vector<std::string> bad_values(const OptionSpec& s) {
  return std::visit(
      [&](auto m) -> std::vector<std::string> {
        using T = std::remove_reference_t<decltype(EstimatorOptions{}.*m)>;
        if constexpr (std::is_same_v<T, bool>) {
          return {"2"};
        } else {
          const double step = std::is_same_v<T, int> ? 1.0 : std::max(1e-3, 0.5 * s.range.hi);
          return {exact(T(s.range.hi + step)), exact(T(s.range.lo_open ? s.range.lo : s.range.lo - step))};
        }
      },
      s.field);
}

// `text` without its top-level lines for `keys`, then "key: value" for each.
std::string with_keys(const std::string& text, const std::vector<std::pair<std::string, std::string>>& kv) {
  std::istringstream in(text);
  std::ostringstream out;
  for (std::string line; std::getline(in, line);) {
    bool drop = false;
    for (const auto& [k, v] : kv) drop = drop || line.rfind(k + ":", 0) == 0;
    if (!drop) out << line << "\n";
  }
  for (const auto& [k, v] : kv) out << k << ": " << v << "\n";
  return out.str();
}

// The "(file)" / "(--set)" / "(default)" mark print() gives `key`.
std::string source_of(const std::string& printed, const std::string& key) {
  const std::regex line("\n  " + key + " += [^\n]*  \\(([-a-z]+)\\)");
  std::smatch m;
  return std::regex_search(printed, m, line) ? m[1].str() : "(not printed)";
}

using test::LogCapture;

template <typename T>
bool same_value(T field, const std::string& written) {
  if constexpr (std::is_same_v<T, bool>) return field == (written == "true");
  if constexpr (std::is_same_v<T, int>) return field == std::stoi(written);
  return field == std::stod(written);
}

}  // namespace

TEST_CASE("The new keys default to the values the estimator used before they were keys", "[options][table]") {
  const EstimatorOptions o;
  CHECK(o.reprojection_sigma_px == 1.5);
  CHECK(o.settle_tolerance == 0.05);
  CHECK(o.max_alternations == 4);
  CHECK(o.zero_velocity_sigma == 0.01);
  CHECK(o.imu_max_gap == 0.1);
  CHECK(std::llround(o.imu_max_gap * 1e9) == 100'000'000);  // the 100 ms it replaces, exactly
  CHECK(460.0 / o.reprojection_sigma_px == 460.0 / 1.5);
}

TEST_CASE("Every key of the table and the rig, set in the yaml, takes effect and is marked (file)", "[options][table]") {
  ScratchConfig s(kEuroc);
  std::vector<std::pair<std::string, std::string>> kv;
  for (const OptionSpec& spec : option_specs()) kv.emplace_back(spec.key, other_value(spec));
  // The rig keys the EuRoC file does not already carry with other values than the defaults.
  kv.emplace_back("cam0_calib", "\"cam0_pinhole.yaml\"");
  kv.emplace_back("cam1_calib", "\"cam1_pinhole.yaml\"");
  const std::string path = (s.dir / "every_key.yaml").string();
  std::ofstream(path) << with_keys(slurp((s.dir / "euroc_stereo_imu_config.yaml").string()), kv);

  const auto o = EstimatorOptions::load(path);
  const std::string printed = o.print();
  for (const OptionSpec& spec : option_specs()) {
    const std::string written = other_value(spec);
    INFO(spec.key << " written " << written << ", loaded " << o.value(spec.key));
    CHECK(std::visit([&](auto m) { return same_value(o.*m, written); }, spec.field));
    CHECK(source_of(printed, spec.key) == "file");
  }
  CHECK(o.lambda_w == o.regularization_gamma * o.regularization_gamma);
  CHECK(o.use_imu);
  CHECK(o.num_of_cam == 2);
  CHECK(o.image_width == 752);
  CHECK(o.cameras[0]->name() == "PINHOLE");
  CHECK(o.cameras[1]->name() == "PINHOLE");
  CHECK(o.body_T_cam[1](0, 3) == Approx(-0.0198435579556));
  for (const auto& [key, help] : rig_keys()) {
    INFO(key);
    CHECK(source_of(printed, key) == "file");
  }
  CHECK(o.unknown_keys.empty());
}

TEST_CASE("Every key of the table, set with --set, takes effect and is marked (--set)", "[options][table]") {
  std::vector<std::pair<std::string, std::string>> kv;
  for (const OptionSpec& spec : option_specs()) kv.emplace_back(spec.key, other_value(spec));
  const auto o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml", kv);
  const std::string printed = o.print();
  for (const auto& entry : kv) {
    const std::string& key = entry.first;  // not a structured binding: C++17 lambdas cannot capture those
    const std::string& written = entry.second;
    INFO(key << " set " << written << ", got " << o.value(key));
    const OptionSpec& spec = *std::find_if(option_specs().begin(), option_specs().end(),
                                          [&](const OptionSpec& x) { return key == x.key; });
    CHECK(std::visit([&](auto m) { return same_value(o.*m, written); }, spec.field));
    CHECK(source_of(printed, key) == "--set");
  }
  CHECK(o.lambda_w == o.regularization_gamma * o.regularization_gamma);
  CHECK(source_of(printed, "imu") == "file");
}

TEST_CASE("Each key's out-of-range value is rejected on load and on --set, naming the key", "[options][table]") {
  ScratchConfig s(kEuroc);
  const std::string base = slurp((s.dir / "euroc_stereo_imu_config.yaml").string());
  const std::string path = (s.dir / "bad_value.yaml").string();
  EstimatorOptions o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  const std::string before = o.print();
  for (const OptionSpec& spec : option_specs()) {
    for (const std::string& v : bad_values(spec)) {
      INFO(spec.key << ": " << v);
      std::ofstream(path) << with_keys(base, {{spec.key, v}});
      CHECK_THROWS_WITH(EstimatorOptions::load(path),
                        Catch::Contains(path) && Catch::Contains(std::string("'") + spec.key + "'"));
      CHECK_THROWS_WITH(o.apply(spec.key, v), Catch::Contains("--set") && Catch::Contains(std::string("'") + spec.key + "'"));
    }
  }
  CHECK(o.print() == before);  // nothing applied by the failed calls
}

TEST_CASE("window_size 1 and 100000000 are rejected", "[options][table]") {
  ScratchConfig s(kEuroc);
  EstimatorOptions o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  for (const char* v : {"1", "100000000"}) {
    INFO(v);
    const std::string path = s.edit("euroc_stereo_imu_config.yaml", "keyframe_parallax: 10.0",
                                    std::string("keyframe_parallax: 10.0\nwindow_size: ") + v);
    CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains("'window_size'") && Catch::Contains("[4, 50]"));
    CHECK_THROWS_WITH(o.apply("window_size", v), Catch::Contains("'window_size'") && Catch::Contains("[4, 50]"));
  }
  const std::string ok = s.edit("euroc_stereo_imu_config.yaml", "keyframe_parallax: 10.0",
                                "keyframe_parallax: 10.0\nwindow_size: 12");
  CHECK(EstimatorOptions::load(ok).window_size == 12);  // read from the yaml, not only from --set
  CHECK(source_of(EstimatorOptions::load(ok).print(), "window_size") == "file");
}

TEST_CASE("NaN and Inf in the config are rejected naming the key and the file", "[options][table]") {
  ScratchConfig s(kEuroc);
  for (const char* v : {".nan", ".inf", "-.inf"}) {
    INFO(v);
    const std::string a = s.edit("euroc_stereo_imu_config.yaml", "max_solver_time: 0.04", std::string("max_solver_time: ") + v);
    CHECK_THROWS_WITH(EstimatorOptions::load(a), Catch::Contains(a) && Catch::Contains("'max_solver_time'"));
    const std::string b = s.edit("euroc_stereo_imu_config.yaml", "acc_n: 0.1", std::string("acc_n: ") + v);
    CHECK_THROWS_WITH(EstimatorOptions::load(b), Catch::Contains(b) && Catch::Contains("'acc_n'"));
    const std::string c = s.edit("euroc_stereo_imu_config.yaml", "td: 0.0", std::string("td: ") + v);
    CHECK_THROWS_WITH(EstimatorOptions::load(c), Catch::Contains(c) && Catch::Contains("'td'") && Catch::Contains("finite"));
  }
  EstimatorOptions o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  CHECK_THROWS_WITH(o.apply("td", "nan"), Catch::Contains("'td'"));
  CHECK_THROWS_WITH(o.apply("td", "inf"), Catch::Contains("'td'"));
}

TEST_CASE("A key written twice is an error naming the key and the file", "[options][table]") {
  ScratchConfig s(kEuroc);
  const std::string path = s.edit("euroc_stereo_imu_config.yaml", "keyframe_parallax: 10.0",
                                  "keyframe_parallax: 10.0\nmax_cnt: 200");
  CHECK_THROWS_WITH(EstimatorOptions::load(path), Catch::Contains(path) && Catch::Contains("'max_cnt'") &&
                                                      Catch::Contains("more than once"));
}

TEST_CASE("An unknown yaml key is warned, naming it and the file, with the nearest key", "[options][table]") {
  ScratchConfig s(kViode);
  const std::string path = s.edit("calibration_stereo.yaml", "momentum_lambda:   0.2",
                                  "momentum_lamda:   0.3\nmy_own_setting: 1");
  LogCapture log;
  const auto o = EstimatorOptions::load(path);
  CHECK(o.unknown_keys == std::vector<std::string>{"momentum_lamda", "my_own_setting"});
  CHECK(o.lambda_m == 0.2);  // the misspelt key is not read
  const std::string text = log.text.str();
  CHECK_THAT(text, Catch::Contains(path) && Catch::Contains("'momentum_lamda'") &&
                       Catch::Contains("did you mean momentum_lambda?"));
  CHECK_THAT(text, Catch::Contains("'my_own_setting'"));
  CHECK(text.find("my_own_setting' (ignored);") == std::string::npos);  // nothing close to it
}

TEST_CASE("Online calibration asked for (estimate_td, estimate_extrinsic) is warned: it is not done here",
          "[options]") {
  ScratchConfig s(kEuroc);
  std::string path = s.edit("euroc_stereo_imu_config.yaml", "estimate_td: 0", "estimate_td: 1");
  {
    LogCapture log;
    const auto o = EstimatorOptions::load(path);
    CHECK(o.estimate_td);
    CHECK_THAT(log.text.str(), Catch::Contains(path) && Catch::Contains("estimate_td: 1") &&
                                   Catch::Contains("not estimated online"));
  }
  path = s.edit("euroc_stereo_imu_config.yaml", "estimate_extrinsic: 0", "estimate_extrinsic: 1");
  {
    LogCapture log;
    EstimatorOptions::load(path);
    CHECK_THAT(log.text.str(), Catch::Contains(path) && Catch::Contains("not calibrated online"));
  }
  LogCapture log;  // VINS-Fusion's own file asks for neither
  EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  CHECK(log.text.str().find("online") == std::string::npos);
}

TEST_CASE("An unknown --set key names the nearest key and lists the valid ones", "[options][table]") {
  EstimatorOptions o = EstimatorOptions::load(kEuroc + "euroc_stereo_imu_config.yaml");
  CHECK_THROWS_WITH(o.apply("momentum_lamda", "1"),
                    Catch::Contains("did you mean momentum_lambda?") && Catch::Contains("max_cnt") &&
                        Catch::Contains("imu_max_gap") && !Catch::Contains("option list printed at start"));
  CHECK_THROWS_WITH(o.apply("zzzzzzzz", "1"), Catch::Contains("Valid keys:") && !Catch::Contains("did you mean"));
}

TEST_CASE("Every shipped config in the shared data loads without unknown keys", "[options][table]") {
  const fs::path data = fs::path(DYNAVINS_SHARED_DIR) / "data";
  if (!fs::is_directory(data)) {
    WARN("no " << data << ": skipped");
    return;
  }
  int configs = 0;
  for (const auto& e : fs::recursive_directory_iterator(data)) {
    if (e.path().extension() != ".yaml") continue;
    // Estimator configs only: camera files and EuRoC's sensor.yaml are read by their own loaders.
    if (slurp(e.path().string()).find("\nnum_of_cam") == std::string::npos) continue;
    INFO(e.path());
    LogCapture log;
    const auto o = EstimatorOptions::load(e.path().string());
    CHECK(o.unknown_keys.empty());
    CHECK(log.text.str().find("unknown key") == std::string::npos);
    ++configs;
  }
  CHECK(configs >= 5);
}

TEST_CASE("README.md's key table is the one the code generates", "[options][table]") {
  const std::string readme = slurp(std::string(DYNAVINS_SOURCE_DIR) + "/README.md");
  const std::string begin = "<!-- options-table:begin (dynavins info --options-markdown) -->\n";
  const std::string end = "<!-- options-table:end -->";
  const auto b = readme.find(begin), e = readme.find(end);
  REQUIRE(b != std::string::npos);
  REQUIRE(e != std::string::npos);
  const std::string table = readme.substr(b + begin.size(), e - b - begin.size());
  // On a failure, paste `build/bin/dynavins info --options-markdown` between the markers.
  CHECK(table == options_markdown_table());
  for (const OptionSpec& spec : option_specs()) CHECK_THAT(table, Catch::Contains(std::string("| `") + spec.key + "` |"));
}
