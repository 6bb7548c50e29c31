#pragma once
// A sensor source that injects faults into another one, for the estimator-fault test (issue 22): frames
// that go black, a view that moves entirely (a textured wall filling both cameras and sliding across
// them), a burst of frames that never arrive, an IMU bias that jumps. A plain decorator: the wrapped
// source's events pass through in order, changed or left out as the plan says.
#include <cstdint>
#include <memory>
#include <string>
#include <variant>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "io/sensor_source.hpp"

namespace dynavins::test {

/// Windows [from, to) in ns after the first event's sensor time; an empty one (from >= to) injects nothing.
struct FaultPlan {
  int64_t black_from_ns = 0, black_to_ns = 0;  ///< both images all black (a lens cap, a dark tunnel)
  /// Both images show only a textured wall that slides sideways at wall_px_per_s (a truck's side, a train
  /// filling the view): fronto-parallel at wall_disparity_px, so the stereo pair is consistent, and every
  /// feature moves the same way whatever the camera does.
  int64_t wall_from_ns = 0, wall_to_ns = 0;
  double wall_px_per_s = 300.0;
  double wall_disparity_px = 40.0;
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
        if (in(t, plan_.wall_from_ns, plan_.wall_to_ns)) {
          const int shift = static_cast<int>(plan_.wall_px_per_s * 1e-9 * static_cast<double>(t - plan_.wall_from_ns));
          f->left = wall_view(f->left.size(), shift);
          if (!f->right.empty()) f->right = wall_view(f->right.size(), shift + static_cast<int>(plan_.wall_disparity_px));
          ++frames_wall;
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

  int frames_black = 0, frames_wall = 0, frames_dropped = 0;

 private:
  static bool in(int64_t t, int64_t from, int64_t to) { return t >= from && t < to; }

  /// The wall as a camera of `size` sees it, `offset` px along the texture (new buffers every call).
  cv::Mat wall_view(cv::Size size, int offset) {
    if (wall_.empty()) {
      // Blurred noise, corners everywhere; wide enough for the whole slide and the right camera's offset.
      const double slide = plan_.wall_px_per_s * 1e-9 * static_cast<double>(plan_.wall_to_ns - plan_.wall_from_ns);
      cv::Mat noise(size.height, size.width + static_cast<int>(slide + plan_.wall_disparity_px) + 2, CV_8UC1);
      cv::RNG rng(7);
      rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
      cv::GaussianBlur(noise, wall_, cv::Size(0, 0), 2.0);
      cv::normalize(wall_, wall_, 0, 255, cv::NORM_MINMAX);
    }
    return wall_(cv::Rect(offset, 0, size.width, size.height)).clone();
  }

  io::SensorSource& inner_;
  FaultPlan plan_;
  int64_t start_ns_ = -1;
  cv::Mat wall_;
};

}  // namespace dynavins::test
