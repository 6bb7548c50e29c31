#include "stages/estimator/window_gauge.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "stages/estimator/initialization/gravity_alignment.hpp"

namespace dynavins::estimator {
namespace {
double pitch_of(const Eigen::Matrix3d& R) { return std::asin(std::clamp(-R(2, 0), -1.0, 1.0)); }
bool near_vertical(const Eigen::Matrix3d& R) { return std::abs(std::abs(pitch_of(R)) - M_PI / 2) < M_PI / 180.0; }
}  // namespace

WindowGauge WindowGauge::of(const WindowState& s) {
  WindowGauge g;
  g.p0_ = s.p(0);
  g.R0_ = s.q(0).toRotationMatrix();
  return g;
}

void WindowGauge::restore(WindowState& s, int newest) const {
  const Eigen::Matrix3d R0_now = s.q(0).toRotationMatrix();
  const Eigen::Vector3d p0_now = s.p(0);
  const Eigen::Matrix3d dR =
      near_vertical(R0_) || near_vertical(R0_now)
          ? Eigen::Matrix3d(R0_ * R0_now.transpose())
          : Eigen::Matrix3d(Eigen::AngleAxisd(yaw_of(R0_) - yaw_of(R0_now), Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond dq(dR);
  for (int k = 0; k <= newest; ++k) {
    s.p(k) = dR * (s.p(k) - p0_now) + p0_;
    s.q(k) = (dq * s.q(k)).normalized();
    s.v(k) = dR * s.v(k);
  }
}

}  // namespace dynavins::estimator
