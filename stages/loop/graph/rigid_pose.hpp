#pragma once
// A rigid body pose T_W^b (body b in frame W: x_W = q * x_b + p) and the few operations the loop graph
// needs (composition, inverse, yaw). Convention used throughout stages/loop/graph: T_A^B is "the pose of
// B expressed in A", so T_W^k = T_W^m * T_m^k composes left to right like transforms act on points.
// The paper writes the same products in the opposite order (eq. 13-14: T_m^k . T_W^m); only the notation
// differs.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynavins::loop {

struct RigidPose {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

/// a * b: if a = T_A^B and b = T_B^C, the result is T_A^C.
inline RigidPose compose(const RigidPose& a, const RigidPose& b) {
  return RigidPose{a.p + a.q * b.p, (a.q * b.q).normalized()};
}

/// T_B^A from T_A^B.
inline RigidPose inverse(const RigidPose& a) {
  const Eigen::Quaterniond qi = a.q.conjugate();
  return RigidPose{-(qi * a.p), qi};
}

/// Angle wrapped into [-pi, pi).
inline double normalize_angle(double a) {
  constexpr double kPi = 3.14159265358979323846;
  const double w = std::fmod(a + kPi, 2.0 * kPi);
  return (w < 0.0 ? w + 2.0 * kPi : w) - kPi;
}

/// Yaw of the Z-Y-X (yaw, pitch, roll) decomposition R = Rz(yaw) Ry(pitch) Rx(roll), as VINS-Fusion's
/// Utility::R2ypr (there in degrees; radians here).
inline double yaw_of(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

/// Pitch and roll of the same decomposition.
inline double pitch_of(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return std::atan2(-R(2, 0), R(0, 0) * std::cos(yaw) + R(1, 0) * std::sin(yaw));
}
inline double roll_of(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return std::atan2(R(0, 2) * std::sin(yaw) - R(1, 2) * std::cos(yaw),
                    -R(0, 1) * std::sin(yaw) + R(1, 1) * std::cos(yaw));
}

/// Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Quaterniond quat_from_ypr(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .normalized();
}

}  // namespace dynavins::loop
