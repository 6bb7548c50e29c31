#pragma once
// The states of the sliding window as Ceres parameter blocks (layout in parameter_layout.hpp): one pose
// and one speed-bias block per slot, the fixed camera extrinsics, and the IMU preintegration that ends at
// each slot. Slot 0 is the oldest keyframe, slot `newest` the latest frame.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "stages/estimator/parameter_layout.hpp"
#include "stages/estimator/window_features.hpp"
#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator {

struct WindowState {
  explicit WindowState(int window_size) : t_ns(window_size + 1), pose(window_size + 1), speed_bias(window_size + 1),
                                          preint(window_size + 1), still(window_size + 1, 0) {
    for (auto& p : pose) p = {0, 0, 0, 0, 0, 0, 1};
    for (auto& s : speed_bias) s.fill(0.0);
  }

  int size() const { return static_cast<int>(pose.size()); }  ///< window_size + 1 slots

  Eigen::Map<Eigen::Vector3d> p(int k) { return Eigen::Map<Eigen::Vector3d>(pose[k].data()); }
  Eigen::Map<Eigen::Quaterniond> q(int k) { return Eigen::Map<Eigen::Quaterniond>(pose[k].data() + 3); }
  Eigen::Map<Eigen::Vector3d> v(int k) { return Eigen::Map<Eigen::Vector3d>(speed_bias[k].data()); }
  Eigen::Map<Eigen::Vector3d> ba(int k) { return Eigen::Map<Eigen::Vector3d>(speed_bias[k].data() + 3); }
  Eigen::Map<Eigen::Vector3d> bg(int k) { return Eigen::Map<Eigen::Vector3d>(speed_bias[k].data() + 6); }
  Eigen::Vector3d p(int k) const { return Eigen::Map<const Eigen::Vector3d>(pose[k].data()); }
  Eigen::Quaterniond q(int k) const { return Eigen::Map<const Eigen::Quaterniond>(pose[k].data() + 3); }

  /// cam `c`'s pose in the world at slot k.
  CameraPose camera(int k, int c = 0) const { return camera_at(p(k), q(k), c); }
  /// cam `c`'s pose in the world for the body pose (p_wb, q_wb).
  CameraPose camera_at(const Eigen::Vector3d& p_wb, const Eigen::Quaterniond& q_wb, int c = 0) const {
    const Eigen::Matrix3d R_wb = q_wb.toRotationMatrix();
    const Eigen::Quaterniond q_bc(Eigen::Map<const Eigen::Quaterniond>(extrinsic[c].data() + 3));
    const Eigen::Vector3d p_bc(Eigen::Map<const Eigen::Vector3d>(extrinsic[c].data()));
    return {R_wb * q_bc.toRotationMatrix(), p_wb + R_wb * p_bc};
  }

  /// Copies every state of slot `from` into slot `to` (preintegration moved).
  void move_slot(int from, int to) {
    t_ns[to] = t_ns[from];
    pose[to] = pose[from];
    speed_bias[to] = speed_bias[from];
    preint[to] = std::move(preint[from]);
    still[to] = still[from];
  }

  std::vector<int64_t> t_ns;
  std::vector<std::array<double, kPoseSize>> pose;
  std::vector<std::array<double, kSpeedBiasSize>> speed_bias;
  std::array<std::array<double, kPoseSize>, 2> extrinsic{};  ///< body_T_cam0, body_T_cam1
  std::vector<std::unique_ptr<imu::ImuPreintegration>> preint;   ///< preint[k]: slot k-1 -> k (null at slot 0)
  std::vector<uint8_t> still;  ///< 1: slot k was found at rest (standstill_detector.hpp); its velocity is held at 0
};

}  // namespace dynavins::estimator
