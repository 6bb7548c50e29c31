#include "stages/estimator/sliding_window_estimator.hpp"

#include <chrono>
#include <climits>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <spdlog/spdlog.h>

#include "stages/common/so3.hpp"
#include "stages/estimator/imu_path_from_rest.hpp"
#include "stages/estimator/initialization/gravity_alignment.hpp"
#include "stages/estimator/initialization/gyro_bias_estimator.hpp"
#include "stages/estimator/initialization/init_frame_history.hpp"
#include "stages/estimator/initialization/mono_initializer.hpp"
#include "stages/estimator/standstill_detector.hpp"
#include "stages/estimator/window_features.hpp"
#include "stages/estimator/window_optimizer.hpp"
#include "stages/estimator/window_state.hpp"

namespace dynavins::estimator {

namespace {

using Clock = std::chrono::steady_clock;

/// Before tracking, a frame that continues fewer of the previous frame's features restarts the window:
/// as many as a frame's own stereo pose needs (initialize_stereo), so the window stays one connected view.
constexpr int kMinTrackedToInitialize = 10;

WindowSolveOptions solve_options(const EstimatorOptions& o, const EstimatorMode& m) {
  WindowSolveOptions s;
  s.loss = m.loss;
  s.stereo = m.stereo;
  s.max_iterations = o.max_num_iterations;
  s.max_solver_time_s = o.max_solver_time;
  s.gravity = o.g_norm;
  s.sqrt_info = kNominalFocalPx / o.reprojection_sigma_px;
  s.weights.lambda_w = o.lambda_w;
  s.weights.lambda_m = o.momentum_on ? o.lambda_m : 0.0;
  s.weights.max_momentum_count = o.window_size;
  s.alternating_converge = o.alternating_converge;
  s.settle_tolerance = o.settle_tolerance;
  s.max_alternations = o.max_alternations;
  s.zero_velocity_sigma = o.zero_velocity_sigma;
  s.acc_bias_prior_sigma = o.acc_bias_prior_sigma;
  s.margin_feature_thresh = o.margin_feature_thresh;
  s.weighted_huber = o.weighted_huber;
  s.weights.kept_full_weight = o.kept_full_weight;
  s.weights.residual_per_component = o.residual_per_component;
  s.weights.oracle_labels = o.oracle_labels;
  s.mono_max_depth_baselines = o.mono_max_depth_baselines;
  return s;
}

StandstillOptions standstill_options(const EstimatorOptions& o) {
  StandstillOptions s;
  s.enabled = o.zupt;
  s.max_speed = o.zupt_max_velocity;
  s.max_disparity_px = o.zupt_max_disparity;
  return s;
}

Eigen::Isometry3d extrinsic_of(const std::array<double, kPoseSize>& e) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(e[6], e[3], e[4], e[5]).toRotationMatrix();
  T.translation() = Eigen::Vector3d(e[0], e[1], e[2]);
  return T;
}

}  // namespace

struct SlidingWindowEstimator::Impl {
  Impl(const EstimatorOptions& o, EstimatorMode m)
      : opt(o), mode(m), W(o.window_size), state(o.window_size), optimizer(solve_options(o, m)),
        slot_seq(o.window_size + 1, 0), slot_image(o.window_size + 1),
        init_history(kMaxInitStride * o.window_size + 1) {
    if (m.stereo && o.num_of_cam < 2) throw std::invalid_argument("stereo mode needs num_of_cam: 2 in " + o.config_file);
    for (int c = 0; c < std::min<int>(2, static_cast<int>(o.body_T_cam.size())); ++c) {
      const Eigen::Quaterniond q(o.body_T_cam[c].linear());
      const Eigen::Vector3d p = o.body_T_cam[c].translation();
      state.extrinsic[c] = {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()};
    }
    if (o.body_T_cam.size() < 2) state.extrinsic[1] = state.extrinsic[0];
    T_c0c1 = extrinsic_of(state.extrinsic[0]).inverse() * extrinsic_of(state.extrinsic[1]);
    // The mono weight step reads the tracks' past (window_optimizer.cpp, history_inconsistent).
    if (!m.stereo && m.loss == BaLoss::Dynavins) features.set_max_past(o.mono_history_keyframes);
  }

  WindowEstimate process(const TrackedFrame& frame, const PreintegratedInterval* imu);
  void reset_all();
  bool predict_newest(const PreintegratedInterval& imu, std::string* why);
  bool initialize_stereo(std::string* why);
  MonoInitResult run_mono_init(const std::vector<InitWindowFrame>& window) const;
  MonoInitResult try_mono_window() const;
  bool initialize_mono_strided(double std_to_beat, bool* keep_second_newest);
  void apply_mono_init(const MonoInitResult& r);
  void clear_window();
  void place_frame(const TrackedFrame& frame);
  void pnp_newest();
  void note_blind_run();
  std::string failure_reason(const Eigen::Vector3d& last_p, const Eigen::Quaterniond& last_q);
  void slide(bool keep_second_newest);
  bool imu_agrees_still();
  void follow_rest_path(bool still);
  void fill_output(WindowEstimate& e);
  Keyframe make_keyframe(int slot) const;
  /// Appends the keyframes of slots [0, end) not handed out yet (time order).
  void emit_keyframes(int end, std::vector<Keyframe>& out);
  SlotCameraPose cams() const {
    return [this](int k) { return state.camera(k, 0); };
  }

  EstimatorOptions opt;
  EstimatorMode mode;
  int W;
  WindowState state;
  WindowFeatures features;
  WindowOptimizer optimizer;
  Eigen::Isometry3d T_c0c1 = Eigen::Isometry3d::Identity();
  int newest = -1;  ///< slot of the latest frame; -1 when empty
  bool tracking = false;
  bool gravity_aligned = false;
  std::string last_init_failure;  ///< last reason initialisation failed, logged when it changes
  std::string last_fail_reason;   ///< reason of the last failed frame (a reset or a frame dropped before tracking)
  // Per slot, moved with the slot (slide): the tracked frame's seq and left image (shallow), for keyframes.
  std::vector<int64_t> slot_seq;
  std::vector<cv::Mat> slot_image;
  int64_t last_emitted_t_ns = INT64_MIN;  ///< newest keyframe handed out (each goes out once)
  /// Longest stride of a mono initialisation window: every 4th of the last 4W+1 frames (2 s at 20 Hz).
  static constexpr int kMaxInitStride = 4;
  InitFrameHistory init_history;  ///< mono, before tracking: the last 4W+1 frames (initialize_mono_strided)
  int scale_failures = 0;         ///< consecutive mono attempts with the parallax but not the scale
  ImuStillVelocity imu_still;     ///< zupt_imu: the IMU's velocity since the last moving solve
  ImuPathFromRest rest_path;      ///< zupt_imu: the IMU-only path from the last frame at rest
  bool judge_on_rest_path = false;  ///< zupt_imu: the solve left that path; the weight step uses it
  int64_t blind_since_ns = -1;  ///< first frame of the current run tracking fewer than 2 features (max_blind_time)
};

void SlidingWindowEstimator::Impl::clear_window() {
  const auto extrinsic = state.extrinsic;  // fixed from config: survives resets
  state = WindowState(W);
  state.extrinsic = extrinsic;
  features.clear();
  for (cv::Mat& m : slot_image) m.release();
  newest = -1;
  gravity_aligned = false;
}

void SlidingWindowEstimator::Impl::reset_all() {
  clear_window();
  imu_still.restart(Eigen::Vector3d::Zero());
  rest_path.clear();
  judge_on_rest_path = false;
  blind_since_ns = -1;
  optimizer.reset();
  init_history.clear();
  scale_failures = 0;
  tracking = false;
}

// zupt_imu: the image found the newest frame still; is the IMU's velocity since the last moving solve small
// too? (standstill_detector.hpp)
bool SlidingWindowEstimator::Impl::imu_agrees_still() {
  if (!opt.zupt_imu || !state.preint[newest]) return true;
  const int i = newest - 1;
  imu_still.add(*state.preint[newest], state.q(i), state.ba(i), state.bg(i), opt.g_norm);
  return imu_still.velocity().norm() < opt.zupt_max_velocity;
}

// zupt_imu: carries the IMU-only path from the last rest frame on to the newest frame, or ends it: at a new
// rest (re-anchored after the solve), when the IMU chain breaks, or once every slot of the window is past
// the rest frame (nothing before the drive-off is left to hold the solve, and the weights have their
// momentum by then).
void SlidingWindowEstimator::Impl::follow_rest_path(bool still) {
  if (rest_path.empty()) return;
  const imu::ImuPreintegration* pre = state.preint[newest].get();
  if (still || !pre || state.t_ns[0] > rest_path.anchor_t_ns()) {
    rest_path.clear();
    judge_on_rest_path = false;
    return;
  }
  rest_path.extend(state.t_ns[newest], *pre, opt.g_norm);
}

void SlidingWindowEstimator::Impl::place_frame(const TrackedFrame& frame) {
  ++newest;
  state.t_ns[newest] = frame.t_ns;
  slot_seq[newest] = frame.seq;
  slot_image[newest] = frame.image;  // shallow copy, released when the frame leaves the window
}

bool SlidingWindowEstimator::Impl::predict_newest(const PreintegratedInterval& imu, std::string* why) {
  const int i = newest - 1, j = newest;
  if (imu.t_begin_ns != state.t_ns[i]) {
    *why = "IMU interval starts at " + std::to_string(imu.t_begin_ns) + " ns, previous frame at " +
           std::to_string(state.t_ns[i]) + " ns";
    return false;
  }
  auto pre = std::make_unique<imu::ImuPreintegration>(imu.preint);
  const Eigen::Vector3d ba = state.ba(i), bg = state.bg(i);
  if (pre->linearized_ba() != ba || pre->linearized_bg() != bg) pre->repropagate(ba, bg);
  if (!gravity_aligned) {
    // First IMU of the run: level the first frame with the mean specific force (VINS' initFirstIMUPose).
    Eigen::Vector3d f = Eigen::Vector3d::Zero();
    for (const ImuSample& smp : pre->samples()) f += smp.acc;
    state.q(i) = Eigen::Quaterniond(gravity_aligned_rotation(f / pre->samples().size()));
    gravity_aligned = true;
  }
  Eigen::Vector3d p_j, v_j;
  Eigen::Quaterniond q_j;
  pre->predict(state.p(i), state.q(i), state.v(i), ba, bg, opt.g_norm, p_j, q_j, v_j);
  state.p(j) = p_j;
  state.v(j) = v_j;
  state.q(j) = q_j;
  state.ba(j) = ba;
  state.bg(j) = bg;
  state.preint[j] = std::move(pre);
  return true;
}

void SlidingWindowEstimator::Impl::pnp_newest() {
  // Pose of the newest frame from the window's triangulated points (VINS-Fusion's initFramePoseByPnP),
  // with RANSAC so that a moving object cannot drag it; the IMU prediction is the initial guess.
  std::vector<cv::Point3f> pts;
  std::vector<cv::Point2f> obs;
  for (const auto& [id, f] : features.all()) {
    if (!f.has_depth || f.start_slot >= newest || f.end_slot() != newest) continue;
    const CameraPose a = state.camera(f.start_slot, 0);
    const Eigen::Vector3d p_w = a.R * (Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0) / f.inv_depth) + a.p;
    const Eigen::Vector2d& xy = f.obs.back().xy;
    pts.emplace_back(p_w.x(), p_w.y(), p_w.z());
    obs.emplace_back(xy.x(), xy.y());
  }
  if (pts.size() < 10) return;
  const CameraPose guess = state.camera(newest, 0);
  const Eigen::Matrix3d R_cw = guess.R.transpose();
  const Eigen::Vector3d t_cw = -R_cw * guess.p;
  cv::Mat R_cv, rvec, tvec;
  cv::eigen2cv(R_cw, R_cv);
  cv::Rodrigues(R_cv, rvec);
  cv::eigen2cv(t_cw, tvec);
  std::vector<int> inliers;
  const bool ok = cv::solvePnPRansac(pts, obs, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, true, 100,
                                     3.0 / kNominalFocalPx, 0.99, inliers, cv::SOLVEPNP_ITERATIVE);
  if (!ok || inliers.size() < 10) return;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R_cw_new;
  Eigen::Vector3d t_cw_new;
  cv::cv2eigen(R_cv, R_cw_new);
  cv::cv2eigen(tvec, t_cw_new);
  // cam pose -> body pose through the fixed extrinsic.
  const Eigen::Isometry3d T_bc = extrinsic_of(state.extrinsic[0]);
  const Eigen::Matrix3d R_wc = R_cw_new.transpose();
  const Eigen::Vector3d p_wc = -R_wc * t_cw_new;
  const Eigen::Matrix3d R_wb = R_wc * T_bc.linear().transpose();
  state.q(newest) = Eigen::Quaterniond(R_wb).normalized();
  state.p(newest) = p_wc - R_wb * T_bc.translation();
}

bool SlidingWindowEstimator::Impl::initialize_stereo(std::string* why) {
  // VINS-Fusion's stereo-inertial start: poses by PnP on stereo points while the window fills, then the
  // gyroscope bias from those rotations, velocities from the positions, and a full window solve.
  int with_depth = 0;
  for (const auto& [id, f] : features.all()) with_depth += f.has_depth ? 1 : 0;
  if (with_depth < 30) {
    *why = "only " + std::to_string(with_depth) + " stereo points in the window";
    return false;
  }
  // Every frame needs a pose of its own from the stereo points (pnp_newest: at least 10): a frame that saw
  // none (black images just after a reset) holds an IMU guess only, and velocities differenced from it
  // start the new track at the wrong speed, to jump once that frame leaves the window (test_vio_faults).
  std::vector<int> seen(newest + 1, 0);  // stereo points observed in each slot, the anchors' own included
  for (const auto& [id, f] : features.all()) {
    if (!f.has_depth) continue;
    for (int k = f.start_slot; k <= f.end_slot(); ++k) ++seen[k];
  }
  for (int k = 0; k <= newest; ++k) {
    if (seen[k] < 10) {
      *why = "window frame " + std::to_string(k) + " sees only " + std::to_string(seen[k]) + " stereo points";
      return false;
    }
  }
  std::vector<Eigen::Matrix3d> R_wb;
  std::vector<const imu::ImuPreintegration*> pre;
  for (int k = 0; k <= newest; ++k) {
    R_wb.push_back(state.q(k).toRotationMatrix());
    if (k > 0) pre.push_back(state.preint[k].get());
  }
  const Eigen::Vector3d dbg = estimate_gyro_bias(R_wb, pre);
  // The window's visual rotations must agree with the gyroscope up to one constant bias. Measured RMS of
  // what the fit leaves per frame interval: 0.003-0.013 deg on sim scenes, 0.004 deg on the real EuRoC
  // clip; 0.1-1.2 deg with frames of a view that moves as a whole (test_vio_faults' sliding wall).
  const double fit_rms_deg = gyro_bias_fit_rms_rad(R_wb, pre, dbg) * 180.0 / M_PI;
  if (fit_rms_deg > 1.0) {
    *why = "camera rotations disagree with the gyroscope by " + std::to_string(fit_rms_deg) +
           " deg RMS per frame after the bias fit (need <= 1 deg)";
    return false;
  }
  if (dbg.norm() > 0.5) {
    *why = "gyroscope bias estimate " + std::to_string(dbg.norm()) + " rad/s is implausible";
    return false;
  }
  for (int k = 0; k <= newest; ++k) {
    state.bg(k) += dbg;
    if (k > 0) state.preint[k]->repropagate(state.ba(k - 1), state.bg(k - 1));
  }
  // Velocities by central differences of the PnP positions (the solve refines them with the IMU).
  for (int k = 0; k <= newest; ++k) {
    const int a = std::max(0, k - 1), b = std::min(newest, k + 1);
    const double dt = (state.t_ns[b] - state.t_ns[a]) * 1e-9;
    if (dt > 0) state.v(k) = (state.p(b) - state.p(a)) / dt;
  }
  return true;
}

MonoInitResult SlidingWindowEstimator::Impl::run_mono_init(const std::vector<InitWindowFrame>& window) const {
  const Eigen::Isometry3d T_bc = extrinsic_of(state.extrinsic[0]);
  MonoInitOptions mo;
  mo.alignment.gravity_norm = opt.g_norm;
  return initialize_mono(window, T_bc.linear(), T_bc.translation(), mo);
}

/// The latest W+1 frames (the window as filled), tried as they are; nothing applied.
MonoInitResult SlidingWindowEstimator::Impl::try_mono_window() const {
  std::vector<InitWindowFrame> window(newest + 1);
  for (int k = 0; k <= newest; ++k) {
    window[k].t = state.t_ns[k] * 1e-9;
    window[k].preint = k > 0 ? state.preint[k].get() : nullptr;
  }
  for (const auto& [id, f] : features.all()) {
    for (size_t o = 0; o < f.obs.size(); ++o) window[f.start_slot + o].features[id] = f.obs[o].xy;
  }
  return run_mono_init(window);
}

/// One frame in 2, 3 and 4 of the history (the strides whose whole span it holds): the same W+1 slots over
/// 2-4 times the time. A start from rest reaches the parallax test late in its acceleration, where the
/// latest W+1 frames (0.5 s) see it nearly constant (the free gravity's tilt absorbs a constant
/// acceleration) over baselines so short that pixel noise pulls their least-squares scale toward zero:
/// 0.45-0.65 of the truth on ten of the bench's mono scenes, 0.37-0.78 on twelve street draws. The window
/// starts from the candidate with the lowest relative scale std, if below `std_to_beat` (the latest W+1
/// frames' own, when they passed): 0.57-1.63 of the truth on those ten scenes, 1.00 on `street_none`, and
/// the window then holds the start of the acceleration (README, "Street scenes"). Tried on copies; only on
/// success is the window rebuilt from those frames, so a failure leaves the consecutive window as it was.
bool SlidingWindowEstimator::Impl::initialize_mono_strided(double std_to_beat, bool* keep_second_newest) {
  MonoInitResult best;
  std::vector<HistoryFrame> best_frames;
  int best_stride = 0;
  for (int stride = 2; stride <= kMaxInitStride && init_history.size() >= stride * W + 1; ++stride) {
    std::vector<HistoryFrame> frames = init_history.strided(stride, W + 1);
    std::vector<InitWindowFrame> window(frames.size());
    std::vector<std::unique_ptr<imu::ImuPreintegration>> preints;
    for (size_t k = 0; k < frames.size(); ++k) {
      window[k].t = frames[k].frame.t_ns * 1e-9;
      for (const TrackedFeature& tf : frames[k].frame.features) window[k].features[tf.id] = tf.xy;
      if (k == 0) continue;
      // As predict_newest builds them before initialisation: linearised at the state's zero biases.
      preints.push_back(std::make_unique<imu::ImuPreintegration>(frames[k].imu->preint));
      if (!preints.back()->linearized_ba().isZero() || !preints.back()->linearized_bg().isZero())
        preints.back()->repropagate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
      window[k].preint = preints.back().get();
    }
    MonoInitResult r = run_mono_init(window);
    if (!r.success) {
      spdlog::debug("t={:.3f} s: one frame in {} of the last {} does not initialise: {}", window.back().t, stride,
                    stride * W + 1, r.reason);
    } else if (r.scale_relative_std < std_to_beat &&
               (best_stride == 0 || r.scale_relative_std < best.scale_relative_std)) {
      best = std::move(r);
      best_frames = std::move(frames);
      best_stride = stride;
    }
  }
  if (best_stride == 0) return false;

  clear_window();
  for (const HistoryFrame& h : best_frames) {
    place_frame(h.frame);
    if (newest > 0) {
      std::string why;
      if (!predict_newest(*h.imu, &why)) throw std::logic_error("initialize_mono_strided: " + why);
      state.preint[newest]->repropagate(state.preint[newest]->linearized_ba(), best.bg);  // as on the copies
    }
    *keep_second_newest = features.add_frame(newest, h.frame, opt.keyframe_parallax / kNominalFocalPx, false);
  }
  const double span = (best_frames.back().frame.t_ns - best_frames.front().frame.t_ns) * 1e-9;
  if (std::isfinite(std_to_beat))
    spdlog::info("mono initialisation on one frame in {} of the last {} ({:.2f} s): scale relative std {:.3f} "
                 "against {:.3f} of the latest {}", best_stride, best_stride * W + 1, span, best.scale_relative_std,
                 std_to_beat, W + 1);
  else
    spdlog::info("mono initialisation on one frame in {} of the last {} ({:.2f} s): the latest {} had the parallax "
                 "but not the scale {} times in a row", best_stride, best_stride * W + 1, span, W + 1, W);
  apply_mono_init(best);
  return true;
}

void SlidingWindowEstimator::Impl::apply_mono_init(const MonoInitResult& r) {
  // At info: mono accuracy hinges on this scale (the accelerometer bias is taken as zero here, as in VINS).
  spdlog::info("mono initialisation: SfM reference frame {} ({:.2f} px RMS), scale {:.3f} (relative std {:.3f}), "
               "bg ({:.4f}, {:.4f}, {:.4f}), newest speed {:.2f} m/s",
               r.sfm_reference_frame, r.sfm_rms_reprojection_px, r.scale, r.scale_relative_std, r.bg.x(), r.bg.y(),
               r.bg.z(), r.v_wb[newest].norm());
  for (int k = 0; k <= newest; ++k) {
    state.q(k) = Eigen::Quaterniond(r.R_wb[k]).normalized();
    state.p(k) = r.p_wb[k];
    state.v(k) = r.v_wb[k];
    state.bg(k) = r.bg;
  }
  for (auto& [id, f] : features.all()) {
    f.has_depth = false;
    auto it = r.depths.find(id);
    if (it != r.depths.end() && it->second.anchor_frame == f.start_slot && it->second.depth > 0.1) {
      f.inv_depth = 1.0 / it->second.depth;
      f.has_depth = true;
    }
  }
}

/// Starts or ends the run of frames tracking fewer than 2 features from the previous frame (blind_since_ns).
void SlidingWindowEstimator::Impl::note_blind_run() {
  if (features.last_tracked_count() >= 2) {
    blind_since_ns = -1;
  } else if (blind_since_ns < 0) {
    blind_since_ns = state.t_ns[newest];
  }
}

std::string SlidingWindowEstimator::Impl::failure_reason(const Eigen::Vector3d& last_p,
                                                        const Eigen::Quaterniond& last_q) {
  // VINS-Fusion's failureDetection thresholds, but for the "little feature" one: VINS-Fusion only logs it and
  // goes on. A truck crossing close in front hides every static corner for a moment, and the IMU carries the
  // window through that; a view lost for longer than max_blind_time (black images, a covered lens) resets.
  if (blind_since_ns >= 0) {
    const int64_t blind_ns = state.t_ns[newest] - blind_since_ns;
    if (blind_ns >= std::llround(opt.max_blind_time * 1e9))
      return fmt::format("fewer than 2 features tracked for {:.2f} s (max_blind_time)", blind_ns * 1e-9);
  }
  if (state.ba(newest).norm() > 2.5) return "accelerometer bias estimate above 2.5 m/s^2";
  if (state.bg(newest).norm() > 1.0) return "gyroscope bias estimate above 1 rad/s";
  const Eigen::Vector3d dp = state.p(newest) - last_p;
  if (dp.norm() > 5.0) return "position jumped more than 5 m in one frame";
  if (std::abs(dp.z()) > 1.0) return "height jumped more than 1 m in one frame";
  const double angle = Eigen::AngleAxisd(last_q.conjugate() * state.q(newest)).angle();
  if (angle > 50.0 * M_PI / 180.0) return "orientation jumped more than 50 degrees in one frame";
  return {};
}

void SlidingWindowEstimator::Impl::slide(bool keep_second_newest) {
  if (keep_second_newest) {
    if (tracking) optimizer.marginalize_oldest(state, newest, features);
    features.remove_oldest(cams(), tracking);  // before the initialisation the poses mean nothing
    for (int k = 0; k < newest; ++k) {
      state.move_slot(k + 1, k);
      slot_seq[k] = slot_seq[k + 1];
      slot_image[k] = std::move(slot_image[k + 1]);  // the oldest's image is released here
    }
    state.preint[0].reset();
  } else {
    if (tracking) optimizer.marginalize_second_newest(state, newest);
    // Fold the newest interval into the second newest's so the IMU chain stays unbroken.
    imu::ImuPreintegration& merged = *state.preint[newest - 1];
    const auto& samples = state.preint[newest]->samples();
    for (size_t k = 1; k < samples.size(); ++k) merged.integrate(samples[k]);
    features.remove_slot(newest - 1, cams());
    auto keep = std::move(state.preint[newest - 1]);
    state.move_slot(newest, newest - 1);
    state.preint[newest - 1] = std::move(keep);
    slot_seq[newest - 1] = slot_seq[newest];
    slot_image[newest - 1] = std::move(slot_image[newest]);  // the dropped frame's image is released here
  }
  state.preint[newest].reset();
  --newest;
}

void SlidingWindowEstimator::Impl::fill_output(WindowEstimate& e) {
  e.status = EstimatorStatus::Tracking;
  NavState& ns = e.state;
  ns.t_ns = state.t_ns[newest];
  ns.p_wb = state.p(newest);
  ns.q_wb = state.q(newest);
  ns.v_wb = state.v(newest);
  ns.bias_acc = state.ba(newest);
  ns.bias_gyr = state.bg(newest);
  e.features.t_ns = ns.t_ns;
  for (const auto& [id, f] : features.all()) {
    if (!f.in_ba() || f.times_solved == 0) continue;
    const CameraPose a = state.camera(f.start_slot, 0);
    WeightedFeature wf;
    wf.id = id;
    wf.u = static_cast<float>(f.obs.back().px.x());
    wf.v = static_cast<float>(f.obs.back().px.y());
    wf.has_right = f.obs.back().has_right;  // never in mono mode (the window keeps no right observations)
    if (wf.has_right) {
      wf.u_r = static_cast<float>(f.obs.back().px_right.x());
      wf.v_r = static_cast<float>(f.obs.back().px_right.y());
    }
    wf.p_w = a.R * (Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0) / f.inv_depth) + a.p;
    wf.weight = static_cast<float>(mode.loss == BaLoss::Dynavins ? f.weight : 1.0);
    wf.times_solved = f.times_solved;
    wf.sim_label = f.sim_label;
    e.features.features.push_back(wf);
  }
}

Keyframe SlidingWindowEstimator::Impl::make_keyframe(int slot) const {
  Keyframe kf;
  kf.t_ns = state.t_ns[slot];
  kf.seq = slot_seq[slot];
  kf.p_wb = state.p(slot);
  kf.q_wb = state.q(slot);
  const auto& e = state.extrinsic[0];
  kf.p_bc = Eigen::Vector3d(e[0], e[1], e[2]);
  kf.q_bc = Eigen::Quaterniond(e[6], e[3], e[4], e[5]);
  kf.image = slot_image[slot];  // shallow copy
  for (const auto& [id, f] : features.all()) {
    if (f.start_slot > slot || f.end_slot() < slot) continue;
    const FeatureObservation& o = f.obs[slot - f.start_slot];
    KeyframePoint p;
    p.id = id;
    p.px = o.px;
    p.xy = o.xy;
    if (f.has_depth && f.inv_depth > 0) {
      const CameraPose a = state.camera(f.start_slot, 0);
      p.p_w = a.R * (Eigen::Vector3d(f.obs[0].xy.x(), f.obs[0].xy.y(), 1.0) / f.inv_depth) + a.p;
      p.has_p_w = true;
    }
    p.weight = static_cast<float>(mode.loss == BaLoss::Dynavins ? f.weight : 1.0);
    kf.points.push_back(p);
  }
  return kf;
}

void SlidingWindowEstimator::Impl::emit_keyframes(int end, std::vector<Keyframe>& out) {
  for (int k = 0; k < end; ++k) {
    if (state.t_ns[k] <= last_emitted_t_ns) continue;
    out.push_back(make_keyframe(k));
    last_emitted_t_ns = state.t_ns[k];
  }
}

WindowEstimate SlidingWindowEstimator::Impl::process(const TrackedFrame& frame, const PreintegratedInterval* imu) {
  const auto t0 = Clock::now();
  WindowEstimate e;
  e.t_ns = frame.t_ns;
  e.seq = frame.seq;
  auto finish = [&](WindowEstimate& out) -> WindowEstimate {
    out.solve.total_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    return out;
  };
  // `latest_slot`: the slot of the latest frame before this one when the failure came before the solve
  // (slots below it are keyframes with the last Tracking poses: handed out), -1 after the solve (dropped).
  // One event per failure: "reset: <why>" when tracking is lost (status Reset, what the run counts as a
  // reset). Before tracking (just after a reset, e.g. on every frame of a long IMU outage) nothing is lost
  // but this frame: "not initialised: <why>", once until the reason changes.
  auto fail = [&](const std::string& why, int latest_slot) -> WindowEstimate {
    const bool was_tracking = tracking;
    const bool repeat = !was_tracking && why == last_fail_reason;
    last_fail_reason = why;
    if (was_tracking) spdlog::warn("estimator reset at t={:.3f} s: {}", frame.t_ns * 1e-9, why);
    else if (!repeat) spdlog::info("frame at t={:.3f} s not estimated (not initialised): {}", frame.t_ns * 1e-9, why);
    if (was_tracking && latest_slot > 0) emit_keyframes(latest_slot, e.finished_keyframes);
    reset_all();
    e.status = was_tracking ? EstimatorStatus::Reset : EstimatorStatus::Initializing;
    e.event = was_tracking ? "reset: " + why : repeat ? std::string() : "not initialised: " + why;
    return finish(e);
  };

  if (newest >= 0 && imu == nullptr) return fail("no IMU between frames", newest);
  if (imu && imu->has_gap && imu->max_gap_ns > std::llround(opt.imu_max_gap * 1e9)) {
    return fail("IMU gap of " + std::to_string(imu->max_gap_ns / 1'000'000) + " ms", newest);
  }
  if (imu && imu->has_gap) e.event = "imu gap of " + std::to_string(imu->max_gap_ns / 1'000'000) + " ms bridged";

  // Place the frame in the next slot, with its IMU-predicted state.
  place_frame(frame);
  if (newest > 0) {
    std::string why;
    if (!predict_newest(*imu, &why)) return fail(why, newest - 1);
  }
  last_fail_reason.clear();  // this frame is in: the next failure is a new event
  const Eigen::Vector3d last_p = newest > 0 ? Eigen::Vector3d(state.p(newest - 1)) : Eigen::Vector3d::Zero();
  const Eigen::Quaterniond last_q = newest > 0 ? state.q(newest - 1) : Eigen::Quaterniond::Identity();
  bool keep_second_newest =
      features.add_frame(newest, frame, opt.keyframe_parallax / kNominalFocalPx, mode.stereo);

  if (!tracking) {
    // A view that changed entirely (the end of a wall sliding past, light back after black frames) breaks
    // the window in two unrelated parts: start the initialisation window again from the next frame.
    if (newest > 0 && features.last_tracked_count() < kMinTrackedToInitialize)
      return fail("only " + std::to_string(features.last_tracked_count()) +
                      " features tracked from the previous frame: initialisation window restarted",
                  newest);
    if (!mode.stereo && opt.mono_init_wide_window) init_history.push(frame, imu);
    if (mode.stereo) {
      if (newest > 0) pnp_newest();  // from points triangulated in earlier frames
      features.triangulate(cams(), T_c0c1, true);
    }
    if (newest < W) return finish(e);  // still filling the window
    std::string why;
    bool sfm_succeeded = false;
    bool ok = false;
    if (mode.stereo) {
      ok = initialize_stereo(&why);
    } else {
      const MonoInitResult r = try_mono_window();
      ok = r.success;
      sfm_succeeded = r.sfm_succeeded;
      why = r.reason;
      // The latest W+1 frames passed: a longer span in the same slots may tell the scale better.
      if (ok && !(opt.mono_init_wide_window && initialize_mono_strided(r.scale_relative_std, &keep_second_newest)))
        apply_mono_init(r);
    }
    scale_failures = !ok && sfm_succeeded ? scale_failures + 1 : 0;
    // After W windows in a row with the parallax but not the scale: the longer spans alone.
    if (scale_failures >= W && opt.mono_init_wide_window)
      ok = initialize_mono_strided(std::numeric_limits<double>::infinity(), &keep_second_newest);
    if (!ok) {
      // Each new reason once at info (a standing camera would otherwise say the same every frame).
      if (why != last_init_failure) spdlog::info("not initialised yet at t={:.3f} s: {}", frame.t_ns * 1e-9, why);
      last_init_failure = why;
      // Drop the oldest and keep collecting: the window tried is always the latest W+1 frames. (VINS slides
      // by the keyframe decision here, a wider window when moving slowly; measured for mono on the sim
      // scenes it started ~1.5 s earlier with a 4-5 % scale error on none/low/night: not taken.)
      slide(true);
      return finish(e);
    }
    e.solve = optimizer.solve(state, newest, features);
    tracking = true;
    init_history.clear();  // its images with it
    e.event = "initialized";
    spdlog::info("estimator initialised at t={:.3f} s ({} mode, {} BA)", frame.t_ns * 1e-9,
                 mode.stereo ? "stereo" : "mono", to_string(mode.loss));
  } else {
    // At rest? Judged on the IMU-predicted rotation and the last solve's weights and speed, before this solve.
    const Eigen::Matrix3d R_prev_new = state.camera(newest - 1).R.transpose() * state.camera(newest).R;
    const StandstillCheck rest =
        check_standstill(features, newest, R_prev_new, state.v(newest - 1).norm(), standstill_options(opt));
    const bool still = rest.still && imu_agrees_still();
    state.still[newest] = still ? 1 : 0;
    e.standstill = still;
    follow_rest_path(still);
    features.triangulate(cams(), T_c0c1, mode.stereo);
    // Once the solve has left the IMU's path it has shown that it follows something else: the path judges
    // until it ends, not only while the solve is away from it (it comes back because of that judging).
    if (!rest_path.empty() && !judge_on_rest_path &&
        rest_path.departed(state.t_ns[newest], state.p(newest), opt.acc_n)) {
      judge_on_rest_path = true;
      spdlog::debug("t={:.3f}: the solve left the IMU's path from the rest at {:.3f}; the weights are judged on it",
                    frame.t_ns * 1e-9, rest_path.anchor_t_ns() * 1e-9);
    }
    e.solve = optimizer.solve(state, newest, features, judge_on_rest_path ? &rest_path : nullptr);
    e.judged_on_rest_path = judge_on_rest_path;
    if (!still) {
      imu_still.restart(state.v(newest));
    } else if (opt.zupt_imu && mode.stereo && imu_still.has_biases()) {
      // Stereo only: in mono the solve's scale is the IMU's own estimate, and a departure is as much that
      // scale settling after a stop as anything followed (standstill_minute, mono: 0.022 -> 0.024 m, a 0.29 m
      // jump at the drive-off; README, "Street scenes").
      rest_path.anchor(state.t_ns[newest], state.p(newest), state.q(newest), imu_still.velocity(), state.v(newest),
                       imu_still.ba(), imu_still.bg());
    }
    features.remove_bad_depths();
    note_blind_run();
    const std::string why = failure_reason(last_p, last_q);
    if (!why.empty()) return fail(why, -1);
    if (blind_since_ns == state.t_ns[newest]) {  // the first frame of a blind run: say so (events, LCM status)
      if (!e.event.empty()) e.event += "; ";
      e.event += fmt::format("blind: fewer than 2 features tracked from the previous frame, the IMU carries the "
                             "estimate for up to max_blind_time = {} s",
                             opt.max_blind_time);
    }
  }
  spdlog::debug("t={:.3f} p=({:.3f},{:.3f},{:.3f}) v=({:.3f},{:.3f},{:.3f}) ba={:.3f} bg={:.4f} ba_ms={:.1f} it={} alt={} feats={} kf={} still={}",
                frame.t_ns * 1e-9, state.p(newest).x(), state.p(newest).y(), state.p(newest).z(), state.v(newest).x(),
                state.v(newest).y(), state.v(newest).z(), state.ba(newest).norm(), state.bg(newest).norm(), e.solve.ba_ms,
                e.solve.ceres_iterations, e.solve.alternations, e.solve.features_in_window, keep_second_newest,
                e.standstill);
  e.keyframe = keep_second_newest;
  fill_output(e);
  // The oldest keyframe leaves the window now, with its final pose and the features before they go.
  if (keep_second_newest) emit_keyframes(1, e.finished_keyframes);
  const auto t_m = Clock::now();
  slide(keep_second_newest);
  e.solve.marginalization_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_m).count();
  return finish(e);
}

SlidingWindowEstimator::SlidingWindowEstimator(const EstimatorOptions& options, EstimatorMode mode)
    : impl_(std::make_unique<Impl>(options, mode)) {
  if (options.oracle_labels != 0 && mode.loss == BaLoss::Dynavins)
    spdlog::warn("oracle_labels = {}: a diagnostic, the simulator's labels overrule the weights in the state step "
                 "(no effect on input without labels); not an estimate to report as the method's",
                 options.oracle_labels);
}
SlidingWindowEstimator::~SlidingWindowEstimator() = default;
SlidingWindowEstimator::SlidingWindowEstimator(SlidingWindowEstimator&&) noexcept = default;
SlidingWindowEstimator& SlidingWindowEstimator::operator=(SlidingWindowEstimator&&) noexcept = default;

WindowEstimate SlidingWindowEstimator::process(const TrackedFrame& frame, const PreintegratedInterval* imu) {
  return impl_->process(frame, imu);
}

NavState SlidingWindowEstimator::latest_state() const {
  NavState s;
  const Impl& m = *impl_;
  if (m.newest < 0) return s;
  // After a slide the newest frame sits one slot down.
  const int k = m.newest;
  s.t_ns = m.state.t_ns[k];
  s.p_wb = m.state.p(k);
  s.q_wb = m.state.q(k);
  s.v_wb = Eigen::Map<const Eigen::Vector3d>(m.state.speed_bias[k].data());
  s.bias_acc = Eigen::Map<const Eigen::Vector3d>(m.state.speed_bias[k].data() + 3);
  s.bias_gyr = Eigen::Map<const Eigen::Vector3d>(m.state.speed_bias[k].data() + 6);
  return s;
}

std::vector<Keyframe> SlidingWindowEstimator::flush_keyframes() {
  std::vector<Keyframe> out;
  Impl& m = *impl_;
  if (m.tracking && m.newest > 0) m.emit_keyframes(m.newest, out);
  return out;
}

bool SlidingWindowEstimator::tracking() const { return impl_->tracking; }

}  // namespace dynavins::estimator
