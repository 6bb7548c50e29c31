#pragma once
// Feature observations of one frame as the initialisation sees them.

#include <map>

#include <Eigen/Core>

namespace dynavins::estimator {

/// Feature id -> observation (x, y) on the cam0 normalized image plane (z = 1).
using FrameFeatures = std::map<int, Eigen::Vector2d>;

}  // namespace dynavins::estimator
