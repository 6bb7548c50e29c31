#pragma once
// Every option of the front end and estimator, loaded from a VINS-Fusion or DynaVINS yaml as the
// user wrote it (OpenVINS style: a struct that loads and prints itself).
//
// Each scalar key is declared once, in the option table of estimator_options.cpp (key, field, range,
// unit, help); its default is the field's initializer below. The yaml loader, `--set`, print() and
// the README's key table (options_markdown_table()) all read that table. Adding a key: a field here and
// one line in the table. The rig keys (imu, num_of_cam, image_*, cam*_calib, body_T_cam*) are read
// from the file only, explicitly in load().
//
// DynaVINS keys, read with the authors' code's meaning (url-kaist/dynaVINS, config/viode):
//   regularization_lambda = gamma: their regularization residual is gamma*(1-w), so the paper's
//                           lambda_w = gamma^2 (stored in lambda_w; the paper's default 1.0 when absent).
//   momentum_lambda       = lambda_m of the momentum term (paper III-D), used as given; default 0.2.
//   alternating_converge  = fraction of feature weights that must have settled before the
//                           alternating (weights <-> states) optimization stops; default 0.9.
//   margin_feature_thresh = features whose weight is below it are left out of marginalization; 0.1.
//   dyna_on / momentum_on = switches (true/false or 0/1); both default true.
// max_solver_time is in seconds (Ceres' budget), whatever VINS-Fusion's comment says.

#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "stages/common/camera_model.hpp"

namespace dynavins {

struct EstimatorOptions {
  std::string config_file;

  // Sensors.
  bool use_imu = true;                    ///< key imu
  int num_of_cam = 1;                     ///< 1 (mono) or 2 (stereo)
  std::vector<std::string> camera_files;  ///< resolved cam0_calib / cam1_calib paths
  std::vector<CameraModelPtr> cameras;
  std::vector<Eigen::Isometry3d> body_T_cam;  ///< camera -> body (IMU) frame, one per camera
  int image_width = 0, image_height = 0;
  int estimate_extrinsic = 0;  ///< 0 fixed, 1 refine around body_T_cam, 2 calibrate from scratch

  // Feature tracker (VINS-Fusion's defaults when absent).
  int max_cnt = 150;
  double min_dist = 30;  ///< pixels
  double freq = 10;      ///< Hz of published tracking; 0 = every image
  double F_threshold = 1.0;
  bool show_track = false;
  bool flow_back = true;
  /// Ours, not VINS-Fusion's: align each track's first patch after the KLT (tracker_options.hpp); 0 gives
  /// VINS-Fusion's plain frame-to-frame KLT.
  bool patch_refine = true;
  /// VINS-Mono's key: contrast-limited histogram equalisation (CLAHE) of every image before tracking.
  bool equalize = false;
  /// Ours: the tracker learns which tracks the robust BA rejected (weight < 0.5): they stop counting
  /// against max_cnt, and fresh corners keep clear of the moving objects they form
  /// (StereoTracker::set_rejected). No effect with the Huber loss, which rejects nothing. Verdicts judged
  /// on the IMU path from a rest (zupt_imu) are not fed back: that path drifts, and its wrong verdicts on
  /// the static scene would steer fresh corners onto a truck that drives off with the camera. Measured in
  /// bench/results/seed_sweep.md (stops 44-45).
  bool rejected_feedback = true;

  // Optimization.
  double max_solver_time = 0.04;  ///< seconds
  int max_num_iterations = 8;
  double keyframe_parallax = 10.0;  ///< pixels
  int window_size = 10;             ///< sliding window (fixed at compile time in VINS-Fusion)
  double reprojection_sigma_px = 1.5;  ///< px at the nominal 460 px focal length (VINS-Fusion's 1.5)
  double settle_tolerance = 0.05;  ///< a weight has settled when it moved less than this in one step
  int max_alternations = 4;        ///< weights <-> states rounds per window solve (dynavins)
  double zero_velocity_sigma = 0.01;  ///< m/s, of the zero-velocity factor on frames found at rest
  /// m/s², ours (issue 23): zero-mean prior on the accelerometer bias at the start, carried on by the
  /// marginalisation (a filter's initial bias covariance); 0 = off, as VINS-Fusion. Off by default: in stereo
  /// it helps the city-block drive and costs `none`, the once-turning streets and the night (README).
  double acc_bias_prior_sigma = 0.0;
  double imu_max_gap = 0.1;  ///< s; a longer IMU outage inside an interval resets the estimator
  /// s, ours: how long the IMU alone carries the estimate while fewer than 2 features are tracked from the
  /// previous frame (a truck crossing close in front: `street_rush`), before the estimator resets. VINS-Fusion
  /// never resets for this (it logs "little feature"); 0 = reset at once, as this project did before.
  double max_blind_time = 3.0;

  // IMU noise (continuous-time standard deviations); required when imu is 1.
  double acc_n = 0.1, gyr_n = 0.01, acc_w = 0.001, gyr_w = 0.0001, g_norm = 9.81;
  bool estimate_td = false;
  double td = 0.0;  ///< seconds; image clock + td = IMU clock

  // DynaVINS (see the mapping above).
  bool dyna_on = true;
  double regularization_gamma = 1.0;  ///< key regularization_lambda as written
  double lambda_w = 1.0;              ///< = regularization_gamma^2, the paper's lambda_w
  bool momentum_on = true;
  double lambda_m = 0.2;  ///< key momentum_lambda
  double alternating_converge = 0.9;
  double margin_feature_thresh = 0.1;
  /// Ours, not the paper's: keep VINS-Fusion's per-observation Huber loss under the per-feature weights
  /// (dynavins mode). A weight judges a whole track; the Huber loss still bounds one bad observation of a
  /// kept track (a one-frame KLT slip). 0 gives the paper's eq. 4 exactly (weights replace the Huber loss).
  bool weighted_huber = true;
  /// Ours, not the paper's: the state step of the alternation gives a kept feature (eq. 10 weight at or
  /// above the weight of a one-sigma track, 0.5 at lambda_w = 1) its full weight, as Huber does, and a
  /// rejected one its weight relative to that (feature_weights.hpp, state_step_weight). 0 (default) = the
  /// paper's w_j^2 on every feature; off by default: over noise draws it helped the street scenes and
  /// hurt `none` and `high` (README, "Street scenes").
  bool kept_full_weight = false;
  /// Ours: r_j of the weight step is the mean squared whitened residual per residual component (2 per
  /// observation), so r_j = 1 is a track at exactly the configured noise (feature_weights.hpp). 0
  /// (default) = per observation (a track at the configured noise then has r_j ~ 2 and is rejected);
  /// off by default for the same measured reason as kept_full_weight.
  bool residual_per_component = false;
  /// Diagnostic for simulated input (0 = off): the simulator's labels overrule the weights in the state
  /// step (1 static at full weight, 2 moving at 0, 3 both; feature_weights.hpp), to measure how much of an
  /// error the weights' verdicts cause. Warned when set; no effect where there are no labels.
  int oracle_labels = 0;
  /// Ours (dynavins, mono only; 0 = off): a track whose best-fit depth is beyond K times the baseline it
  /// was seen over, while the median depth of the tracks in use is within K times that baseline, stays out
  /// of the state step and the prior (its weight stays eq. 10's): its depth is not observable, and a point
  /// moving with the camera looks exactly like it (window_optimizer.cpp, depth_unobservable; README,
  /// "Street scenes"). 30 = a parallax of 1.9 deg.
  double mono_max_depth_baselines = 30.0;
  /// Ours (dynavins, mono only; 0 = off): each track keeps its observations in up to this many keyframes
  /// after they leave the window, with their estimated poses; a track that, over those and the window
  /// together, does not fit one static point (r_j beyond λw) stays out of the state step and the prior.
  /// A point riding with the camera a few metres ahead fits a static one within a window, not over the
  /// distance before it (window_optimizer.cpp, history_inconsistent; README, "Street scenes").
  int mono_history_keyframes = 16;
  /// Ours (mono): besides the latest window_size + 1 frames, one frame in 2, 3 or 4 of the last
  /// 4 window_size + 1 (the same slots over 2-4 times the time). When the latest frames initialise, the
  /// window starts from whichever candidate's scale is most certain; when window_size attempts in a row had
  /// the parallax but not the scale, the longer spans are tried alone. A start from rest reaches the
  /// parallax late in its acceleration, where the latest frames see it nearly constant and their scale is
  /// poor or missing (README, "Street scenes").
  bool mono_init_wide_window = true;
  /// Ours, not the paper's: zero-velocity update (standstill_detector.hpp), with OpenVINS' key names and
  /// defaults. A frame whose kept features show less than `zupt_max_disparity` px of rotation-compensated
  /// motion while the last solve's speed is under `zupt_max_velocity` m/s has its velocity held at zero.
  bool zupt = true;
  double zupt_max_velocity = 0.1;  ///< m/s
  double zupt_max_disparity = 0.5;  ///< px (median, at VINS' nominal 460 px focal length)
  /// Ours (issue 23): the IMU arbitrates around a standstill. A frame is at rest only if the velocity the
  /// IMU integrated since the last moving solve is under `zupt_max_velocity` too (a truck driving off with
  /// the camera keeps the image still), and (stereo) once the solve departs from the IMU-only path from the
  /// last rest frame by more than 3 σ of `acc_n`, the weight step judges the frames after that rest frame
  /// on the path until the window has moved past it (imu_path_from_rest.hpp).
  bool zupt_imu = true;

  std::set<std::string> keys_from_file;      ///< which options the file set (the rest are defaults)
  std::set<std::string> keys_from_override;  ///< which options a command line `--set key=value` set
  /// Keys of the file that are neither ours nor known VINS-Fusion / DynaVINS keys (each warned at load).
  std::vector<std::string> unknown_keys;

  /// Loads `path`; throws ConfigError naming key and file on missing or wrongly typed keys.
  static EstimatorOptions load(const std::string& path);
  /// Loads `path`, then applies `overrides` (key, value) in order, as `--set key=value` does.
  static EstimatorOptions load(const std::string& path,
                               const std::vector<std::pair<std::string, std::string>>& overrides);
  /// Sets one scalar option from text (numbers, true/false/1/0), checked like the file's value.
  /// Throws ConfigError with file "--set" naming the key for an unknown key, a key that cannot be
  /// overridden (cameras, image size), or a bad value.
  void apply(const std::string& key, const std::string& value);
  /// Splits "key=value" (both non-empty, whitespace trimmed); throws ConfigError("--set", ...) otherwise.
  static std::pair<std::string, std::string> parse_override(const std::string& text);
  /// Every effective option, one per line, with "(file)", "(--set)" or "(default)".
  std::string print() const;
  /// The effective value of one table key as print() shows it; throws ConfigError for other keys.
  std::string value(const std::string& key) const;
};

/// Values a numeric key accepts: [lo, hi], or (lo, hi] when lo_open.
struct OptionRange {
  double lo = 0, hi = 0;
  bool lo_open = false;
};

/// One scalar key of the option table. The default is `EstimatorOptions{}.*field`.
struct OptionSpec {
  const char* key;
  std::variant<bool EstimatorOptions::*, int EstimatorOptions::*, double EstimatorOptions::*> field;
  OptionRange range;  ///< unused for flags
  const char* unit;   ///< "" when dimensionless
  const char* help;
  bool imu_only = false;  ///< required with imu: 1, not read (nor printed) without
};

/// The option table, in print order.
const std::vector<OptionSpec>& option_specs();
/// The rig keys (read from the file only): name and meaning.
const std::vector<std::pair<std::string, std::string>>& rig_keys();
/// Keys of VINS-Fusion (and VINS-Mono, VINS-Fusion-gpu, the authors' DynaVINS) that we read past.
const std::vector<std::string>& known_unused_keys();
/// Every key of the table and the rig as a Markdown table (README.md's "Configuration keys").
std::string options_markdown_table();

}  // namespace dynavins
