#include "stages/estimator/initialization/gravity_alignment.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace dynavins::estimator {

double yaw_of(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

Eigen::Matrix3d gravity_aligned_rotation(const Eigen::Vector3d& mean_specific_force) {
  // Smallest rotation taking f onto +z, then the yaw removed: a rotation about z keeps +z fixed.
  const Eigen::Matrix3d R0 =
      Eigen::Quaterniond::FromTwoVectors(mean_specific_force.normalized(), Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  return Eigen::AngleAxisd(-yaw_of(R0), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0;
}

Eigen::Matrix3d rotation_aligning_gravity(const Eigen::Vector3d& g_c0) {
  // Gravity acceleration points down, the specific force of a body at rest points up.
  return gravity_aligned_rotation(-g_c0);
}

}  // namespace dynavins::estimator
