#pragma once
// Feature observations of one frame as the initialisation sees them.

#include <cstdint>
#include <map>

#include <Eigen/Core>

namespace dynavins::estimator {

/// Feature id as the tracker numbers them (64-bit: never truncated, so distinct tracks never merge).
using FeatureId = int64_t;

/// Feature id -> observation (x, y) on the cam0 normalized image plane (z = 1).
using FrameFeatures = std::map<FeatureId, Eigen::Vector2d>;

}  // namespace dynavins::estimator
