#include "stages/common/estimator_options.hpp"

#include <iomanip>
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
  if (o.margin_feature_thresh < 0 || o.margin_feature_thresh > 1) r.fail("margin_feature_thresh", "must be in [0, 1]");
  return o;
}

std::string EstimatorOptions::print() const {
  std::ostringstream s;
  s << std::setprecision(10) << std::boolalpha;
  auto line = [&](const std::string& key, const auto& value, const char* note = "") {
    s << "  " << std::left << std::setw(22) << key << " = " << value << "  ("
      << (keys_from_file.count(key) ? "file" : "default") << ")" << note << "\n";
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
  return s.str();
}

}  // namespace dynavins
