#pragma once
// The IMU-only path from the last frame found at rest (ours, issue 23; key `zupt_imu`; stereo).
//
// Why: when a car drives off with a truck a few metres ahead that drives off with it, nothing in the
// images tells the static scene from the truck: at rest both fitted, and the truck is the larger part of
// the view, so the joint solve follows it (the estimated speed lags the truth, the static tracks are then
// rejected, and the error stays: README, "Street scenes"). The IMU, integrated from a state known to be at
// rest, knows the drive-off to centimetres for the seconds the window takes to move past the rest frame.
// So once the solved path departs from this one by more than the IMU's noise allows (departed()), the
// weight step (paper eq. 10) measures each feature's residual on this path instead of on the solved
// states; the state step is unchanged. Only then: judged on the path from the start, the static scenes
// lost 4 % of their static tracks and up to 2x in ATE (README, "Street scenes"); where nothing drives off
// with the camera the two paths agree and the solved one is the better judge.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynavins::imu {
class ImuPreintegration;
}

namespace dynavins::estimator {

class ImuPathFromRest {
 public:
  struct Pose {
    int64_t t_ns = 0;
    Eigen::Vector3d p = Eigen::Vector3d::Zero();                ///< body position in the world
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();      ///< body orientation in the world
  };

  /// Starts the path at a frame found at rest: its solved pose and biases, and the velocity the IMU
  /// integrated up to it (`v`, near zero; see ImuStillVelocity). `v_solved`, the solve's velocity there (held
  /// near zero by the zero-velocity factor), sets how far apart the two paths may drift from the start
  /// without either having followed anything (departed()).
  void anchor(int64_t t_ns, const Eigen::Vector3d& p, const Eigen::Quaterniond& q, const Eigen::Vector3d& v,
              const Eigen::Vector3d& v_solved, const Eigen::Vector3d& ba, const Eigen::Vector3d& bg);

  /// Appends the frame at `t_ns`, reached from the path's last frame through `pre` (its biases corrected to
  /// the anchor's). No-op on an empty path.
  void extend(int64_t t_ns, const imu::ImuPreintegration& pre, double gravity);

  void clear() { poses_.clear(); }
  bool empty() const { return poses_.empty(); }
  /// Time of the rest frame the path starts from (the path must not be empty).
  int64_t anchor_t_ns() const { return poses_.front().t_ns; }
  /// The path's pose of the frame at `t_ns` after the anchor; null when the path does not reach it.
  const Pose* after_anchor(int64_t t_ns) const;
  /// Is the solved body position `p` of the frame at `t_ns` further from the path's than the two starts'
  /// velocity difference explains (|v - v_solved| T) plus 3 σ of white accelerometer noise of density
  /// `acc_n` [m/s²/√Hz] integrated twice (σ = acc_n T^1.5 / √3), T the time since the anchor? False where
  /// the path does not reach the frame.
  bool departed(int64_t t_ns, const Eigen::Vector3d& p, double acc_n) const;

 private:
  std::vector<Pose> poses_;  ///< [0]: the anchor
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero(), ba_ = Eigen::Vector3d::Zero(), bg_ = Eigen::Vector3d::Zero();
  double start_speed_gap_ = 0.0;  ///< |v - v_solved| at the anchor [m/s]
};

}  // namespace dynavins::estimator
