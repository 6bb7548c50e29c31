#pragma once
// Is the camera at rest between the window's two newest frames? The test behind the zero-velocity
// factor (factors/zero_velocity_factor.hpp), after OpenVINS' zero-velocity disparity check:
//   - the median rotation-compensated displacement of the features seen in both frames is below
//     `max_disparity_px` (on the z = 1 plane, scaled by kNominalFocalPx like the keyframe parallax);
//   - at least `min_features` features enter that median;
//   - the last solve's speed is below `max_speed`, so a camera moving past a scene too far to show
//     parallax in one frame is not stopped by it;
//   - with `zupt_imu` (ours), the velocity the IMU integrated since the last moving solve is below
//     `max_speed` too (ImuStillVelocity below).
// Features the robust BA rejected (weight below `min_weight`) are left out, so a truck crossing a still
// camera's view does not hide the standstill, and static points seen while the truck drives do not fake one
// for a moving camera unless they themselves stand still in the image. Not in the paper.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "stages/estimator/window_features.hpp"

namespace dynavins::imu {
class ImuPreintegration;
}

namespace dynavins::estimator {

struct StandstillOptions {
  bool enabled = true;
  double max_disparity_px = 0.5;  ///< OpenVINS' zupt_max_disparity
  double max_speed = 0.1;         ///< m/s; OpenVINS' zupt_max_velocity
  int min_features = 20;
  double min_weight = 0.5;        ///< features below it (rejected by the robust BA) are not counted
};

struct StandstillCheck {
  bool still = false;
  int features = 0;                 ///< features in the median
  double median_disparity_px = -1;  ///< -1 when no feature was seen in both frames
};

/// The IMU's side of the test (ours, issue 23; key `zupt_imu`): the velocity integrated from the last solve
/// that was moving through every frame the image test has found still since, forgetting with a time
/// constant of kForgetS. A vehicle that drives off with the camera (a truck a few metres ahead) keeps the
/// image still while the car accelerates; with the image test alone the zero-velocity factor then held the
/// velocity at zero and the estimate lagged the drive-off. Why it forgets: at a true standstill each
/// frame's velocity change, taken with the window's biases and attitude, is zero only to within what the
/// IMU factor leaves (its noise is the config's), and summed over a minute-long stop it passed 0.1 m/s
/// every 8-10 s (`standstill_minute`: 0.0125 m/s² of drift); forgotten over 1 s it stays near 0.0125 m/s,
/// while a drive-off at 1 m/s² still passes 0.1 m/s within about 0.11 s. The biases are the ones the run
/// of still frames started with: while the zero-velocity factor holds a creeping car at v = 0, the solve
/// explains the IMU's acceleration with the accelerometer bias (`standstill_minute`'s drive-off: still
/// until 0.31 m/s with the window's biases), so the later biases would hide what this is there to see.
class ImuStillVelocity {
 public:
  static constexpr double kForgetS = 1.0;  ///< time constant of the forgetting [s]

  /// The last solve was moving: the integral restarts from its velocity, and the next add() takes the biases.
  void restart(const Eigen::Vector3d& v) {
    v_ = v;
    has_biases_ = false;
  }
  /// Adds one frame interval `pre`, which starts at a frame with orientation `q`; `ba`, `bg` are that
  /// frame's biases, used only by the first add() after a restart.
  void add(const imu::ImuPreintegration& pre, const Eigen::Quaterniond& q, const Eigen::Vector3d& ba,
           const Eigen::Vector3d& bg, double gravity);
  const Eigen::Vector3d& velocity() const { return v_; }
  /// The biases the run of still frames started with (valid when has_biases()).
  bool has_biases() const { return has_biases_; }
  const Eigen::Vector3d& ba() const { return ba_; }
  const Eigen::Vector3d& bg() const { return bg_; }

 private:
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero(), ba_ = Eigen::Vector3d::Zero(), bg_ = Eigen::Vector3d::Zero();
  bool has_biases_ = false;
};

/// Tests slot `newest` against slot `newest - 1`. `R_prev_new` rotates cam0 of the newest frame into cam0 of
/// the previous one (from the IMU-predicted states); `speed` is |v| of the previous frame [m/s].
StandstillCheck check_standstill(const WindowFeatures& features, int newest, const Eigen::Matrix3d& R_prev_new,
                                double speed, const StandstillOptions& options);

}  // namespace dynavins::estimator
