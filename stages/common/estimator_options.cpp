#include "stages/common/estimator_options.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <type_traits>

#include <spdlog/spdlog.h>

#include "stages/common/camera_loader.hpp"
#include "stages/common/config_reader.hpp"

namespace dynavins {

using O = EstimatorOptions;

// The option table: one line per scalar key. Ranges reject what cannot be meant (a window of 1 frame
// gave a 2.7 m ATE, one of 10^8 frames 14 GB); they are not tuning advice.
const std::vector<OptionSpec>& option_specs() {
  static const std::vector<OptionSpec> kTable{
      {"estimate_extrinsic", &O::estimate_extrinsic, {0, 2}, "", "VINS-Fusion: 0 fixed, 1 refine, 2 calibrate; here the extrinsic stays fixed (2 allows no body_T_cam)"},
      // Feature tracker.
      {"max_cnt", &O::max_cnt, {10, 2000}, "", "features kept per frame"},
      {"min_dist", &O::min_dist, {0, 200}, "px", "minimum distance between features"},
      {"freq", &O::freq, {0, 1000}, "Hz", "VINS-Fusion's rate of published tracking (read, not used: every image is tracked)"},
      {"F_threshold", &O::F_threshold, {0, 50, true}, "px", "fundamental-matrix RANSAC threshold (the RANSAC is off, as in VINS-Fusion)"},
      {"show_track", &O::show_track, {}, "", "VINS-Fusion's tracking image (read, not drawn here)"},
      {"flow_back", &O::flow_back, {}, "", "forward-backward check of the temporal KLT"},
      {"patch_refine", &O::patch_refine, {}, "", "align each track's first patch after the KLT (ours); 0 = plain KLT"},
      {"equalize", &O::equalize, {}, "", "VINS-Mono: CLAHE on every image before tracking (dark scenes)"},
      {"rejected_feedback", &O::rejected_feedback, {}, "", "the tracker learns which tracks the robust BA rejected: they stop counting against max_cnt (up to max_cnt more are tracked), and no corner is detected within 2 min_dist of one with another rejected track within 4 min_dist (ours, issue 23; behind a leading truck r_d 1.58 -> 0.88; verdicts judged on the IMU path from a rest are not fed back, README); 0 = every track counts"},
      // Optimization.
      {"max_solver_time", &O::max_solver_time, {0, 3600, true}, "s", "Ceres time budget per window solve"},
      {"max_num_iterations", &O::max_num_iterations, {1, 1000}, "", "Ceres iterations per window solve"},
      {"keyframe_parallax", &O::keyframe_parallax, {0, 200, true}, "px", "keyframe parallax threshold at 460 px focal length"},
      // Mono initialisation needs at least 3 frames; below 4 the window holds too little parallax.
      {"window_size", &O::window_size, {4, 50}, "frames", "sliding window size (window_size + 1 slots)"},
      {"reprojection_sigma_px", &O::reprojection_sigma_px, {0.1, 20}, "px", "reprojection noise at 460 px focal length"},
      {"settle_tolerance", &O::settle_tolerance, {0, 1, true}, "", "a weight moving less than this in one step has settled (dynavins)"},
      {"max_alternations", &O::max_alternations, {1, 20}, "", "weights <-> states rounds per window solve (dynavins)"},
      {"zero_velocity_sigma", &O::zero_velocity_sigma, {1e-4, 1}, "m/s", "sigma of the zero-velocity factor (zupt)"},
      {"acc_bias_prior_sigma", &O::acc_bias_prior_sigma, {0, 10}, "m/s^2", "prior on the accelerometer bias at the start, per axis, kept by the marginalisation (ours, issue 23; off: helps the city-block drive, costs the other streets and the night, README); 0 = off"},
      {"imu_max_gap", &O::imu_max_gap, {0.01, 1}, "s", "an IMU outage longer than this resets the estimator; shorter ones are bridged"},
      {"max_blind_time", &O::max_blind_time, {0, 60}, "s", "while fewer than 2 features are tracked from the previous frame (a truck crossing close in front, black images) the IMU alone carries the estimate, for at most this long, then it resets (ours; VINS-Fusion never resets for it); 0 = reset at once"},
      // IMU (continuous-time standard deviations).
      {"acc_n", &O::acc_n, {0, 10, true}, "m/s^2/sqrt(Hz)", "accelerometer noise", true},
      {"gyr_n", &O::gyr_n, {0, 10, true}, "rad/s/sqrt(Hz)", "gyroscope noise", true},
      {"acc_w", &O::acc_w, {0, 10, true}, "m/s^3/sqrt(Hz)", "accelerometer bias random walk", true},
      {"gyr_w", &O::gyr_w, {0, 10, true}, "rad/s^2/sqrt(Hz)", "gyroscope bias random walk", true},
      {"g_norm", &O::g_norm, {9.5, 10}, "m/s^2", "gravity magnitude", true},
      {"estimate_td", &O::estimate_td, {}, "", "VINS-Fusion: estimate td online; not done here (warned): td stays as set"},
      {"td", &O::td, {-1, 1}, "s", "time offset, image clock + td = IMU clock: frame times are moved by it on input, so outputs are in the IMU clock"},
      // DynaVINS (see estimator_options.hpp for the mapping).
      {"dyna_on", &O::dyna_on, {}, "", "per-feature weights (the authors' switch)"},
      {"regularization_lambda", &O::regularization_gamma, {0, 100}, "", "gamma of the authors' code; lambda_w = gamma^2"},
      {"momentum_on", &O::momentum_on, {}, "", "momentum term on the weights"},
      {"momentum_lambda", &O::lambda_m, {0, 100}, "", "lambda_m of the momentum term"},
      {"alternating_converge", &O::alternating_converge, {0, 1, true}, "", "share of settled weights that ends the alternation"},
      {"margin_feature_thresh", &O::margin_feature_thresh, {0, 1}, "", "features under this weight stay out of the prior"},
      {"weighted_huber", &O::weighted_huber, {}, "", "Huber loss under the weights (ours); 0 = the paper's eq. 4"},
      {"kept_full_weight", &O::kept_full_weight, {}, "", "1: kept features at full weight in the state step (ours, issue 23; off: mixed result, README); 0 = w_j^2 (eq. 11)"},
      {"residual_per_component", &O::residual_per_component, {}, "", "1: r_j per residual component, in units of the configured noise (ours, issue 23; off: mixed result, README); 0 = per observation"},
      {"oracle_labels", &O::oracle_labels, {0, 3}, "", "diagnostic, simulated input only: the simulator's labels overrule the state step's weights, 1 static tracks at full weight, 2 moving ones at 0, 3 both (what a perfect verdict would give); 0 = off"},
      {"mono_max_depth_baselines", &O::mono_max_depth_baselines, {0, 1000}, "", "mono: a track deeper than this many times its baseline, while the median depth of the tracks in use is within that, stays out of the state step (ours, issue 23); 0 = off"},
      {"mono_history_keyframes", &O::mono_history_keyframes, {0, 100}, "", "mono: a track whose observations in up to this many keyframes before the window and in the window do not fit one static point (r_j beyond lambda_w) stays out of the state step (ours, issue 23); 0 = off"},
      {"mono_init_wide_window", &O::mono_init_wide_window, {}, "", "mono: one frame in 2, 3 or 4 of the last 4 window_size + 1 is tried too, in the same slots; the window starts from the one whose scale is most certain, when the latest window_size + 1 pass, or alone after window_size attempts in a row with the parallax but not the scale (ours, issue 23); 0: the latest window_size + 1 only"},
      {"zupt", &O::zupt, {}, "", "zero-velocity update (ours, OpenVINS' keys)"},
      {"zupt_max_velocity", &O::zupt_max_velocity, {0, 10}, "m/s", "at rest only below this speed of the last solve"},
      {"zupt_max_disparity", &O::zupt_max_disparity, {0, 50}, "px", "at rest only below this median rotation-compensated motion"},
      {"zupt_imu", &O::zupt_imu, {}, "", "at rest only if the IMU's velocity since the last moving solve is under zupt_max_velocity too; stereo: a solve that leaves the IMU-only path from the last rest frame (3 sigma of acc_n) has its weights judged on that path (ours, issue 23)"},
  };
  return kTable;
}

const std::vector<std::pair<std::string, std::string>>& rig_keys() {
  static const std::vector<std::pair<std::string, std::string>> kKeys{
      {"imu", "1 with an IMU, 0 without (required)"},
      {"num_of_cam", "1 (mono) or 2 (stereo) (required)"},
      {"image_width", "px (required)"},
      {"image_height", "px (required)"},
      {"cam0_calib", "camodocs camera file, relative to the yaml (required)"},
      {"cam1_calib", "the same for the right camera (stereo)"},
      {"body_T_cam0", "4x4 !!opencv-matrix, camera to IMU body (may be absent with estimate_extrinsic 2)"},
      {"body_T_cam1", "the same for the right camera (stereo)"},
  };
  return kKeys;
}

const std::vector<std::string>& known_unused_keys() {
  static const std::vector<std::string> kKeys{
      // VINS-Fusion (and VINS-Fusion-gpu) configs.
      "imu_topic", "image0_topic", "image1_topic", "output_path", "multiple_thread", "load_previous_pose_graph",
      "pose_graph_save_path", "save_image", "use_gpu", "use_gpu_acc_flow", "use_gpu_ceres",
      // VINS-Mono configs.
      "image_topic", "model_type", "camera_name", "distortion_parameters", "projection_parameters",
      "extrinsicRotation", "extrinsicTranslation", "ex_calib_result_path", "fisheye", "fisheye_mask",
      "loop_closure", "fast_relocalization", "rolling_shutter", "rolling_shutter_tr", "visualize_imu_forward",
      "visualize_camera_size",
      // The authors' DynaVINS configs (visualisation, test switch and their loop closure).
      "show_image_feat_weight", "max_depth", "test_mono", "min_score_static", "min_overlap", "max_keyframe",
      "hypodiff_dist", "hypodiff_yaw", "hypo_regularization", "hypo_alternating_converge", "min_loop"};
  return kKeys;
}

namespace {

constexpr const char* kOverrideSource = "--set";

std::string number(double x) {
  std::ostringstream s;
  s << std::setprecision(10) << x;
  return s.str();
}

template <typename T>
std::string text(const T& v) {
  std::ostringstream s;
  s << std::setprecision(10) << std::boolalpha << v;
  return s.str();
}

template <typename T>
constexpr bool kIsFlag = std::is_same_v<T, bool>;

template <typename T>
const char* type_name() {
  return kIsFlag<T> ? "bool" : std::is_same_v<T, int> ? "int" : "real";
}

std::string range_text(const OptionSpec& s) {
  return std::visit(
      [&](auto m) -> std::string {
        using T = std::remove_reference_t<decltype(EstimatorOptions{}.*m)>;
        if constexpr (kIsFlag<T>) {
          return "true/false";
        } else {
          return (s.range.lo_open ? "(" : "[") + number(s.range.lo) + ", " + number(s.range.hi) + "]";
        }
      },
      s.field);
}

// Empty when `x` is in the key's range, else what is wrong with it.
std::string range_problem(const OptionSpec& s, double x) {
  const OptionRange& g = s.range;
  if (!std::isfinite(x)) return "must be a finite number, got " + number(x);
  if (x < g.lo || x > g.hi || (g.lo_open && x == g.lo))
    return std::string("must be in ") + range_text(s) + (*s.unit ? std::string(" ") + s.unit : "") + ", got " +
           number(x);
  return {};
}

const OptionSpec* find_spec(const std::string& key) {
  for (const OptionSpec& s : option_specs())
    if (key == s.key) return &s;
  return nullptr;
}

bool is_rig_key(const std::string& key) {
  for (const auto& [k, help] : rig_keys())
    if (k == key) return true;
  return false;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// Our key closest to `key` within 2 edits, or "".
std::string nearest_key(const std::string& key) {
  std::string best;
  std::size_t best_d = 3;
  auto consider = [&](const std::string& k) {
    const std::size_t d = edit_distance(key, k);
    if (d < best_d) best = k, best_d = d;
  };
  for (const OptionSpec& s : option_specs()) consider(s.key);
  for (const auto& [k, help] : rig_keys()) consider(k);
  return best;
}

void derive(EstimatorOptions& o) { o.lambda_w = o.regularization_gamma * o.regularization_gamma; }

// Reads one table key from the file (absent: the default stays), checked against its range.
void load_option(const ConfigReader& r, EstimatorOptions& o, const OptionSpec& s) {
  if (s.imu_only && !o.use_imu) return;
  // VINS-Fusion reads the IMU keys unconditionally (a missing one silently becomes 0); with an IMU we insist.
  if (!r.has(s.key)) {
    if (s.imu_only) r.fail(s.key, "required key is missing");
    return;
  }
  std::visit(
      [&](auto m) {
        using T = std::remove_reference_t<decltype(o.*m)>;
        if constexpr (kIsFlag<T>) {
          o.*m = *r.find_bool(s.key);
        } else {
          T v;
          if constexpr (std::is_same_v<T, int>) v = *r.find_int(s.key);
          else v = *r.find_double(s.key);
          const std::string problem = range_problem(s, v);
          if (!problem.empty()) r.fail(s.key, problem);
          o.*m = v;
        }
      },
      s.field);
  o.keys_from_file.insert(s.key);
}

// Top-level keys of the file that are neither ours nor known to be read past; each is warned.
std::vector<std::string> find_unknown_keys(const ConfigReader& r) {
  const auto& unused = known_unused_keys();
  std::vector<std::string> out;
  for (const std::string& k : r.keys()) {
    if (find_spec(k) || is_rig_key(k) || std::find(unused.begin(), unused.end(), k) != unused.end()) continue;
    const std::string near = nearest_key(k);
    spdlog::warn("{}: unknown key '{}' (ignored){}", r.path(), k, near.empty() ? "" : "; did you mean " + near + "?");
    out.push_back(k);
  }
  return out;
}

}  // namespace

EstimatorOptions EstimatorOptions::load(const std::string& path) {
  const ConfigReader r(path);
  EstimatorOptions o;
  o.config_file = path;
  auto rig = [&](const std::string& key, auto& out, auto read) {
    out = (r.*read)(key);
    o.keys_from_file.insert(key);
  };
  rig("imu", o.use_imu, &ConfigReader::get_bool);
  rig("num_of_cam", o.num_of_cam, &ConfigReader::get_int);
  if (o.num_of_cam != 1 && o.num_of_cam != 2) r.fail("num_of_cam", "must be 1 or 2, found " + std::to_string(o.num_of_cam));
  rig("image_width", o.image_width, &ConfigReader::get_int);
  rig("image_height", o.image_height, &ConfigReader::get_int);
  if (o.image_width <= 0) r.fail("image_width", "must be positive");
  if (o.image_height <= 0) r.fail("image_height", "must be positive");

  for (const OptionSpec& s : option_specs()) load_option(r, o, s);

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
  derive(o);
  o.unknown_keys = find_unknown_keys(r);
  // VINS-Fusion would calibrate these online; here they stay as the file gives them, which is said once.
  if (o.estimate_td)
    spdlog::warn("{}: estimate_td: 1, but the time offset is not estimated online here: td = {} s is applied as set",
                 path, o.td);
  if (o.estimate_extrinsic != 0)
    spdlog::warn("{}: estimate_extrinsic: {}, but the camera-IMU extrinsic is not calibrated online here: body_T_cam{} "
                 "is used as {}",
                 path, o.estimate_extrinsic, o.num_of_cam > 1 ? "0/1" : "0",
                 o.estimate_extrinsic == 2 ? "given (identity where absent)" : "given");
  return o;
}

std::string EstimatorOptions::value(const std::string& key) const {
  const OptionSpec* s = find_spec(key);
  if (!s) throw ConfigError(config_file, key, "not a key of the option table");
  return std::visit([&](auto m) { return text(this->*m); }, s->field);
}

std::string EstimatorOptions::print() const {
  std::ostringstream s;
  auto line = [&](const std::string& key, const std::string& value, const std::string& note = "") {
    s << "  " << std::left << std::setw(22) << key << " = " << value << "  ("
      << (keys_from_override.count(key) ? "--set" : keys_from_file.count(key) ? "file" : "default") << ")" << note
      << "\n";
  };
  s << "Estimator options from " << config_file << ":\n";
  line("imu", text(use_imu));
  line("num_of_cam", text(num_of_cam));
  line("image_width", text(image_width));
  line("image_height", text(image_height));
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
  for (const OptionSpec& o : option_specs()) {
    if (o.imu_only && !use_imu) continue;
    line(o.key, value(o.key), *o.unit ? std::string(" [") + o.unit + "]" : "");
    // The one derived option, shown under the key it comes from.
    if (std::string(o.key) == "regularization_lambda")
      s << "  " << std::left << std::setw(22) << "lambda_w" << " = " << text(lambda_w) << "  (derived) = gamma^2\n";
  }
  return s.str();
}

std::string options_markdown_table() {
  std::ostringstream s;
  const EstimatorOptions defaults;
  s << "| Key | Type | Default | Range | Unit | Meaning |\n";
  s << "|---|---|---|---|---|---|\n";
  for (const OptionSpec& o : option_specs()) {
    const std::string type = std::visit(
        [](auto m) { return std::string(type_name<std::remove_reference_t<decltype(EstimatorOptions{}.*m)>>()); },
        o.field);
    s << "| `" << o.key << "` | " << type << " | " << defaults.value(o.key) << " | " << range_text(o) << " | " << o.unit
      << " | " << o.help << (o.imu_only ? " (required with `imu: 1`)" : "") << " |\n";
  }
  for (const auto& [key, help] : rig_keys())
    s << "| `" << key << "` | rig |  |  |  | " << help << "; file only, not `--set` |\n";
  return s.str();
}

namespace {

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
  if (used == 0 || used != v.size() || !std::isfinite(x)) bad(key, "expected a finite number, got '" + v + "'");
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

std::string unknown_override(const std::string& key) {
  const std::string near = nearest_key(key);
  std::string msg = "unknown option";
  if (!near.empty()) msg += "; did you mean " + near + "?";
  msg += " Valid keys:";
  for (const OptionSpec& s : option_specs()) msg += std::string(" ") + s.key;
  return msg;
}

}  // namespace

std::pair<std::string, std::string> EstimatorOptions::parse_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) bad("", "expected key=value, got '" + text + "'");
  std::pair<std::string, std::string> kv{trim(text.substr(0, eq)), trim(text.substr(eq + 1))};
  if (kv.first.empty()) bad("", "empty key in '" + text + "'");
  if (kv.second.empty()) bad(kv.first, "empty value in '" + text + "'");
  return kv;
}

void EstimatorOptions::apply(const std::string& key, const std::string& value) {
  if (is_rig_key(key)) bad(key, "describes the sensor rig and cannot be overridden; edit the yaml");
  const OptionSpec* s = find_spec(key);
  if (!s) bad(key, unknown_override(key));
  std::visit(
      [&](auto m) {
        using T = std::remove_reference_t<decltype(this->*m)>;
        if constexpr (kIsFlag<T>) {
          this->*m = parse_bool(key, value);
        } else {
          T v;
          if constexpr (std::is_same_v<T, int>) v = parse_int(key, value);
          else v = parse_double(key, value);
          const std::string problem = range_problem(*s, v);
          if (!problem.empty()) bad(key, problem);
          this->*m = v;
        }
      },
      s->field);
  derive(*this);
  keys_from_override.insert(key);
}

EstimatorOptions EstimatorOptions::load(const std::string& path,
                                        const std::vector<std::pair<std::string, std::string>>& overrides) {
  EstimatorOptions o = load(path);
  for (const auto& [key, value] : overrides) o.apply(key, value);
  return o;
}

}  // namespace dynavins
