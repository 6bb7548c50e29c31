#pragma once
// Rotations that put a measured gravity direction on the world z axis with zero yaw (VINS-Mono's
// Utility::g2R). World convention of this project: z up, gravity acceleration g_w = (0, 0, -g).

#include <Eigen/Core>

namespace dynavins::estimator {

/// Yaw of R in the Z-Y-X (yaw-pitch-roll) convention: atan2(R(1,0), R(0,0)) [rad].
double yaw_of(const Eigen::Matrix3d& R);

/// Body-to-world rotation R_wb with zero yaw such that R_wb * f = (0, 0, |f|), where f is the mean
/// specific force measured by a (roughly) static accelerometer. f must be non-zero.
Eigen::Matrix3d gravity_aligned_rotation(const Eigen::Vector3d& mean_specific_force);

/// Rotation R_wc0 with zero yaw such that R_wc0 * g_c0 = (0, 0, -|g_c0|): aligns the gravity acceleration
/// g_c0 found in some reference frame c0 (e.g. by visual-inertial alignment) with the world's -z.
Eigen::Matrix3d rotation_aligning_gravity(const Eigen::Vector3d& g_c0);

}  // namespace dynavins::estimator
