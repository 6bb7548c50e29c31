#pragma once
// One time-stamped input of the pipeline, as a replay or live source delivers them in time order.

#include <variant>

#include "messages/sensor_messages.hpp"

namespace dynavins {

using SensorEvent = std::variant<StereoFrame, ImuSample, GroundTruthState>;

/// Sensor time of any event [ns].
inline int64_t event_time_ns(const SensorEvent& e) {
  return std::visit([](const auto& m) { return m.t_ns; }, e);
}

}  // namespace dynavins
