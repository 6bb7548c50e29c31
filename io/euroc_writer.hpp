#pragma once
// Writes sensor events as an EuRoC ASL folder (mav0/cam0, cam1, imu0, state_groundtruth_estimate0),
// the layout VINS-Fusion's EuRoC tools and this project's reader take. Simulated label images go to
// mav0/cam0/labels/ (an extension; other tools ignore it).

#include <fstream>
#include <string>

#include "messages/sensor_event.hpp"

namespace dynavins::io {

class EurocWriter {
 public:
  /// Creates `dir`/mav0/... (the folder must not hold an EuRoC data set already).
  explicit EurocWriter(const std::string& dir);
  void write(const SensorEvent& event);
  /// Flushes the CSV files; throws if anything failed to write.
  void close();
  const std::string& mav0() const { return mav0_; }

 private:
  std::string mav0_;
  std::ofstream cam0_, cam1_, imu_, gt_;
};

}  // namespace dynavins::io
