#pragma once
// A sensor source that injects faults into another one, for the estimator-fault test (issue 22): frames
// that go black, a burst of frames that never arrive, an IMU bias that jumps. A plain decorator: the wrapped
// source's events pass through in order, changed or left out as the plan says.
#include <cstdint>
#include <memory>
#include <string>
#include <variant>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "io/sensor_source.hpp"

namespace dynavins::test {

/// Windows [from, to) in ns after the first event's sensor time; an empty one (from >= to) injects nothing.
struct FaultPlan {
  int64_t black_from_ns = 0, black_to_ns = 0;  ///< both images all black (a lens cap, a dark tunnel)
  int64_t drop_from_ns = 0, drop_to_ns = 0;    ///< stereo frames not delivered at all
  int64_t bias_jump_ns = -1;                   ///< from here on the IMU carries an extra bias (< 0: never)
  Eigen::Vector3d acc_jump = Eigen::Vector3d::Zero();  ///< [m/s^2]
  Eigen::Vector3d gyr_jump = Eigen::Vector3d::Zero();  ///< [rad/s]
};

class FaultInjectionSource final : public io::SensorSource {
 public:
  FaultInjectionSource(io::SensorSource& inner, FaultPlan plan) : inner_(inner), plan_(std::move(plan)) {}

  bool next(SensorEvent& out) override {
    while (inner_.next(out)) {
      if (start_ns_ < 0) start_ns_ = event_time_ns(out);
      const int64_t t = event_time_ns(out) - start_ns_;
      if (auto* f = std::get_if<StereoFrame>(&out)) {
        if (in(t, plan_.drop_from_ns, plan_.drop_to_ns)) {
          ++frames_dropped;
          continue;
        }
        if (in(t, plan_.black_from_ns, plan_.black_to_ns)) {
          // New buffers: the wrapped source may still hold the ones it handed out.
          f->left = cv::Mat::zeros(f->left.size(), f->left.type());
          if (!f->right.empty()) f->right = cv::Mat::zeros(f->right.size(), f->right.type());
          ++frames_black;
        }
      } else if (auto* s = std::get_if<ImuSample>(&out)) {
        if (plan_.bias_jump_ns >= 0 && t >= plan_.bias_jump_ns) {
          s->acc += plan_.acc_jump;
          s->gyr += plan_.gyr_jump;
        }
      }
      return true;
    }
    return false;
  }
  double progress() const override { return inner_.progress(); }
  std::string describe() const override { return inner_.describe() + " with injected faults"; }

  /// Sensor time of the first event [ns] (-1 before it): where the plan's times count from.
  int64_t start_ns() const { return start_ns_; }

  int frames_black = 0, frames_dropped = 0;

 private:
  static bool in(int64_t t, int64_t from, int64_t to) { return t >= from && t < to; }

  io::SensorSource& inner_;
  FaultPlan plan_;
  int64_t start_ns_ = -1;
};

}  // namespace dynavins::test
