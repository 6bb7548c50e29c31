#pragma once
// A recorded sensor stream (EuRoC folder, LCM log, ROS bag) read as events in time order.
// Plain and single-threaded: the replay driver in pipeline/ paces it and feeds the queues.

#include <string>

#include "messages/sensor_event.hpp"

namespace dynavins::io {

class SensorSource {
 public:
  virtual ~SensorSource() = default;
  /// Next event in time order; false at the end. Throws InputError on bad input.
  virtual bool next(SensorEvent& out) = 0;
  /// Fraction of the input consumed, in [0, 1], for progress displays.
  virtual double progress() const = 0;
  /// Where the data comes from, for logs.
  virtual std::string describe() const = 0;
};

}  // namespace dynavins::io
