#include "stages/common/estimator_options.hpp"

#include <cmath>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>

#include <spdlog/spdlog.h>

#include "stages/common/camera_loader.hpp"
#include "stages/common/config_reader.hpp"

namespace dynavins {
namespace {

// Reads an optional key into `out`, remembering that the file set it.
struct Loader {
  const ConfigReader& r;
  EstimatorOptions& o;
  void opt(const std::string& key, int& out) {
    if (auto v = r.find_int(key)) out = *v, o.keys_from_file.insert(key);
  }
  void opt(const std::string& key, double& out) {
    if (auto v = r.find_double(key)) out = *v, o.keys_from_file.insert(key);
  }
  void opt(const std::string& key, bool& out) {
    if (auto v = r.find_bool(key)) out = *v, o.keys_from_file.insert(key);
  }
  template <typename T>
  void req(const std::string& key, T& out) {
    if (!r.has(key)) r.fail(key, "required key is missing");
    opt(key, out);
  }
};

}  // namespace

EstimatorOptions EstimatorOptions::load(const std::string& path) {
  const ConfigReader r(path);
  EstimatorOptions o;
  o.config_file = path;
  Loader l{r, o};

  l.req("imu", o.use_imu);
  l.req("num_of_cam", o.num_of_cam);
  if (o.num_of_cam != 1 && o.num_of_cam != 2) r.fail("num_of_cam", "must be 1 or 2, found " + std::to_string(o.num_of_cam));
  l.req("image_width", o.image_width);
  l.req("image_height", o.image_height);
  if (o.image_width <= 0) r.fail("image_width", "must be positive");
  if (o.image_height <= 0) r.fail("image_height", "must be positive");
  l.opt("estimate_extrinsic", o.estimate_extrinsic);
  if (o.estimate_extrinsic < 0 || o.estimate_extrinsic > 2) r.fail("estimate_extrinsic", "must be 0, 1 or 2");

  for (int i = 0; i < o.num_of_cam; ++i) {
    const std::string calib_key = "cam" + std::to_string(i) + "_calib";
    const std::string T_key = "body_T_cam" + std::to_string(i);
    std::string resolved;
    o.cameras.push_back(load_camera_from_config(path, calib_key, r.get_string(calib_key), &resolved));
    o.camera_files.push_back(resolved);
    o.keys_from_file.insert(calib_key);
    // With estimate_extrinsic 2 VINS-Fusion calibrates from nothing, so the matrix may be absent.
    if (o.estimate_extrinsic == 2 && !r.has(T_key)) {
      o.body_T_cam.push_back(Eigen::Isometry3d::Identity());
    } else {
      o.body_T_cam.push_back(r.get_transform(T_key));
      o.keys_from_file.insert(T_key);
    }
    const auto& cam = *o.cameras.back();
    if (cam.width() != o.image_width || cam.height() != o.image_height)
      spdlog::warn("{}: {} is {}x{} but image_width/image_height say {}x{}", path, resolved, cam.width(),
                   cam.height(), o.image_width, o.image_height);
  }

  l.opt("max_cnt", o.max_cnt);
  l.opt("min_dist", o.min_dist);
  l.opt("freq", o.freq);
  l.opt("F_threshold", o.F_threshold);
  l.opt("show_track", o.show_track);
  l.opt("flow_back", o.flow_back);
  l.opt("patch_refine", o.patch_refine);
  l.opt("max_solver_time", o.max_solver_time);
  l.opt("max_num_iterations", o.max_num_iterations);
  l.opt("keyframe_parallax", o.keyframe_parallax);
  if (o.max_cnt <= 0) r.fail("max_cnt", "must be positive");
  if (o.freq < 0) r.fail("freq", "must be non-negative");

  if (o.use_imu) {
    // VINS-Fusion reads these unconditionally (a missing one silently becomes 0); with an IMU we insist.
    l.req("acc_n", o.acc_n);
    l.req("gyr_n", o.gyr_n);
    l.req("acc_w", o.acc_w);
    l.req("gyr_w", o.gyr_w);
    l.req("g_norm", o.g_norm);
    for (const char* k : {"acc_n", "gyr_n", "acc_w", "gyr_w", "g_norm"})
      if (!(r.get_double(k) > 0)) r.fail(k, "must be positive");
  }
  l.opt("estimate_td", o.estimate_td);
  l.opt("td", o.td);

  l.opt("dyna_on", o.dyna_on);
  l.opt("regularization_lambda", o.regularization_gamma);
  if (o.regularization_gamma < 0) r.fail("regularization_lambda", "must be non-negative");
  o.lambda_w = o.regularization_gamma * o.regularization_gamma;
  l.opt("momentum_on", o.momentum_on);
  l.opt("momentum_lambda", o.lambda_m);
  if (o.lambda_m < 0) r.fail("momentum_lambda", "must be non-negative");
  l.opt("alternating_converge", o.alternating_converge);
  if (o.alternating_converge <= 0 || o.alternating_converge > 1)
    r.fail("alternating_converge", "must be in (0, 1] (fraction of converged weights)");
  l.opt("margin_feature_thresh", o.margin_feature_thresh);
  l.opt("weighted_huber", o.weighted_huber);
  l.opt("zupt", o.zupt);
  l.opt("zupt_max_velocity", o.zupt_max_velocity);
  l.opt("zupt_max_disparity", o.zupt_max_disparity);
  if (o.zupt_max_velocity < 0) r.fail("zupt_max_velocity", "must be non-negative [m/s]");
  if (o.zupt_max_disparity < 0) r.fail("zupt_max_disparity", "must be non-negative [px]");
  if (o.margin_feature_thresh < 0 || o.margin_feature_thresh > 1) r.fail("margin_feature_thresh", "must be in [0, 1]");
  return o;
}

std::string EstimatorOptions::print() const {
  std::ostringstream s;
  s << std::setprecision(10) << std::boolalpha;
  auto line = [&](const std::string& key, const auto& value, const char* note = "") {
    s << "  " << std::left << std::setw(22) << key << " = " << value << "  ("
      << (keys_from_override.count(key) ? "--set" : keys_from_file.count(key) ? "file" : "default") << ")" << note
      << "\n";
  };
  s << "Estimator options from " << config_file << ":\n";
  line("imu", use_imu);
  line("num_of_cam", num_of_cam);
  line("image_width", image_width);
  line("image_height", image_height);
  line("estimate_extrinsic", estimate_extrinsic);
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const std::string n = std::to_string(i);
    line("cam" + n + "_calib", camera_files[i]);
    s << "      " << cameras[i]->describe() << "\n";
    std::ostringstream T;
    T << std::setprecision(10);
    const Eigen::Matrix4d M = body_T_cam[i].matrix();
    for (int r = 0; r < 3; ++r) T << (r ? "; " : "[") << M(r, 0) << ", " << M(r, 1) << ", " << M(r, 2) << ", " << M(r, 3);
    T << "]";
    line("body_T_cam" + n, T.str());
  }
  line("max_cnt", max_cnt);
  line("min_dist", min_dist);
  line("freq", freq);
  line("F_threshold", F_threshold);
  line("show_track", show_track);
  line("flow_back", flow_back);
  line("patch_refine", patch_refine);
  line("max_solver_time", max_solver_time, " [s]");
  line("max_num_iterations", max_num_iterations);
  line("keyframe_parallax", keyframe_parallax);
  line("window_size", window_size);
  if (use_imu) {
    line("acc_n", acc_n);
    line("gyr_n", gyr_n);
    line("acc_w", acc_w);
    line("gyr_w", gyr_w);
    line("g_norm", g_norm);
  }
  line("estimate_td", estimate_td);
  line("td", td, " [s]");
  line("dyna_on", dyna_on);
  line("regularization_lambda", regularization_gamma, " = gamma; lambda_w = gamma^2");
  s << "  " << std::left << std::setw(22) << "lambda_w" << " = " << lambda_w << "  (derived)\n";
  line("momentum_on", momentum_on);
  line("momentum_lambda", lambda_m, " = lambda_m");
  line("alternating_converge", alternating_converge);
  line("margin_feature_thresh", margin_feature_thresh);
  line("weighted_huber", weighted_huber);
  line("zupt", zupt);
  line("zupt_max_velocity", zupt_max_velocity, " [m/s]");
  line("zupt_max_disparity", zupt_max_disparity, " [px]");
  return s.str();
}

namespace {

constexpr const char* kOverrideSource = "--set";

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

[[noreturn]] void bad(const std::string& key, const std::string& problem) {
  throw ConfigError(kOverrideSource, key, problem);
}

double parse_double(const std::string& key, const std::string& v) {
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != v.size() || !std::isfinite(x)) bad(key, "expected a number, got '" + v + "'");
  return x;
}

int parse_int(const std::string& key, const std::string& v) {
  std::size_t used = 0;
  long x = 0;
  try {
    x = std::stol(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != v.size() || x < INT32_MIN || x > INT32_MAX) bad(key, "expected an integer, got '" + v + "'");
  return static_cast<int>(x);
}

bool parse_bool(const std::string& key, const std::string& v) {
  if (v == "true" || v == "1") return true;
  if (v == "false" || v == "0") return false;
  bad(key, "expected true/false/1/0, got '" + v + "'");
}

}  // namespace

std::pair<std::string, std::string> EstimatorOptions::parseOverride(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) bad("", "expected key=value, got '" + text + "'");
  std::pair<std::string, std::string> kv{trim(text.substr(0, eq)), trim(text.substr(eq + 1))};
  if (kv.first.empty()) bad("", "empty key in '" + text + "'");
  if (kv.second.empty()) bad(kv.first, "empty value in '" + text + "'");
  return kv;
}

void EstimatorOptions::apply(const std::string& key, const std::string& value) {
  // Each scalar key: how to parse it and which values the file loader would accept.
  using Setter = std::function<void(EstimatorOptions&, const std::string&, const std::string&)>;
  auto positive_int = [](int EstimatorOptions::*m) -> Setter {
    return [m](EstimatorOptions& o, const std::string& k, const std::string& v) {
      const int x = parse_int(k, v);
      if (x <= 0) bad(k, "must be positive");
      o.*m = x;
    };
  };
  auto real_in = [](double EstimatorOptions::*m, double lo, double hi, bool lo_open, const char* what) -> Setter {
    return [=](EstimatorOptions& o, const std::string& k, const std::string& v) {
      const double x = parse_double(k, v);
      if (x < lo || x > hi || (lo_open && x == lo)) bad(k, what);
      o.*m = x;
    };
  };
  auto flag = [](bool EstimatorOptions::*m) -> Setter {
    return [m](EstimatorOptions& o, const std::string& k, const std::string& v) { o.*m = parse_bool(k, v); };
  };
  const double inf = HUGE_VAL;
  static const std::set<std::string> fixed{"imu", "num_of_cam", "image_width", "image_height", "cam0_calib",
                                           "cam1_calib", "body_T_cam0", "body_T_cam1"};
  const std::map<std::string, Setter> setters{
      {"estimate_extrinsic",
       [](EstimatorOptions& o, const std::string& k, const std::string& v) {
         const int x = parse_int(k, v);
         if (x < 0 || x > 2) bad(k, "must be 0, 1 or 2");
         o.estimate_extrinsic = x;
       }},
      {"max_cnt", positive_int(&EstimatorOptions::max_cnt)},
      {"min_dist", real_in(&EstimatorOptions::min_dist, 0, inf, false, "must be non-negative")},
      {"freq", real_in(&EstimatorOptions::freq, 0, inf, false, "must be non-negative")},
      {"F_threshold", real_in(&EstimatorOptions::F_threshold, 0, inf, true, "must be positive")},
      {"show_track", flag(&EstimatorOptions::show_track)},
      {"flow_back", flag(&EstimatorOptions::flow_back)},
      {"patch_refine", flag(&EstimatorOptions::patch_refine)},
      {"max_solver_time", real_in(&EstimatorOptions::max_solver_time, 0, inf, true, "must be positive [s]")},
      {"max_num_iterations", positive_int(&EstimatorOptions::max_num_iterations)},
      {"keyframe_parallax", real_in(&EstimatorOptions::keyframe_parallax, 0, inf, true, "must be positive")},
      {"window_size", positive_int(&EstimatorOptions::window_size)},
      {"acc_n", real_in(&EstimatorOptions::acc_n, 0, inf, true, "must be positive")},
      {"gyr_n", real_in(&EstimatorOptions::gyr_n, 0, inf, true, "must be positive")},
      {"acc_w", real_in(&EstimatorOptions::acc_w, 0, inf, true, "must be positive")},
      {"gyr_w", real_in(&EstimatorOptions::gyr_w, 0, inf, true, "must be positive")},
      {"g_norm", real_in(&EstimatorOptions::g_norm, 0, inf, true, "must be positive")},
      {"estimate_td", flag(&EstimatorOptions::estimate_td)},
      {"td", real_in(&EstimatorOptions::td, -inf, inf, false, "")},
      {"dyna_on", flag(&EstimatorOptions::dyna_on)},
      {"regularization_lambda",
       [](EstimatorOptions& o, const std::string& k, const std::string& v) {
         const double x = parse_double(k, v);
         if (x < 0) bad(k, "must be non-negative");
         o.regularization_gamma = x;
         o.lambda_w = x * x;
       }},
      {"momentum_on", flag(&EstimatorOptions::momentum_on)},
      {"momentum_lambda", real_in(&EstimatorOptions::lambda_m, 0, inf, false, "must be non-negative")},
      {"alternating_converge", real_in(&EstimatorOptions::alternating_converge, 0, 1, true,
                                       "must be in (0, 1] (fraction of converged weights)")},
      {"margin_feature_thresh",
       real_in(&EstimatorOptions::margin_feature_thresh, 0, 1, false, "must be in [0, 1]")},
      {"weighted_huber", flag(&EstimatorOptions::weighted_huber)},
      {"zupt", flag(&EstimatorOptions::zupt)},
      {"zupt_max_velocity", real_in(&EstimatorOptions::zupt_max_velocity, 0, inf, false, "must be non-negative [m/s]")},
      {"zupt_max_disparity", real_in(&EstimatorOptions::zupt_max_disparity, 0, inf, false, "must be non-negative [px]")},
  };
  if (fixed.count(key)) bad(key, "describes the sensor rig and cannot be overridden; edit the yaml");
  const auto it = setters.find(key);
  if (it == setters.end()) bad(key, "unknown option (see the option list printed at start)");
  it->second(*this, key, value);
  keys_from_override.insert(key);
}

EstimatorOptions EstimatorOptions::load(const std::string& path,
                                        const std::vector<std::pair<std::string, std::string>>& overrides) {
  EstimatorOptions o = load(path);
  for (const auto& [key, value] : overrides) o.apply(key, value);
  return o;
}

}  // namespace dynavins
