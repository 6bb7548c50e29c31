#pragma once
// The estimator stage's input: tracked frames from the tracker stage and preintegrated intervals from
// the IMU stage, fanned into one queue in whatever order the two threads deliver them.

#include <variant>

#include "messages/tracked_frame.hpp"
#include "messages/preintegrated_interval.hpp"

namespace dynavins::estimator {

using EstimatorInput = std::variant<TrackedFrame, PreintegratedInterval>;

}  // namespace dynavins::estimator
