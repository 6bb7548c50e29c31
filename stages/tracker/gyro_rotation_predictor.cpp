#include "stages/tracker/gyro_rotation_predictor.hpp"

#include <algorithm>
#include <stdexcept>

#include "stages/common/so3.hpp"
#include "stages/imu/imu_sample_interpolation.hpp"

namespace dynavins::tracker {

GyroRotationPredictor::GyroRotationPredictor(const Eigen::Isometry3d& body_T_cam0, int64_t max_gap_ns)
    : R_bc_(body_T_cam0.linear()), max_gap_ns_(max_gap_ns) {
  if (max_gap_ns <= 0) throw std::invalid_argument("GyroRotationPredictor: max_gap_ns must be positive");
}

std::optional<Eigen::Matrix3d> GyroRotationPredictor::predict_body(const std::vector<ImuSample>& imu, int64_t t0,
                                                                  int64_t t1, const Eigen::Vector3d& bias) const {
  if (t1 <= t0) return std::nullopt;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  const ImuSample* prev = nullptr;
  bool started = false;
  for (const ImuSample& s : imu) {
    if (prev && s.t_ns <= prev->t_ns) continue;  // out of order or repeated: the IMU stage rejects it too
    if (!prev || s.t_ns <= t0) {
      prev = &s;  // still before the interval: the last such sample is its start
      continue;
    }
    // Segment [prev, s] overlaps (t0, t1].
    if (!started && prev->t_ns > t0) return std::nullopt;  // nothing at or before t0: would extrapolate
    started = true;
    if (s.t_ns - prev->t_ns > max_gap_ns_) return std::nullopt;  // an outage: do not bridge it
    // Midpoint rule on the part of the segment inside [t0, t1], rates interpolated at its ends.
    const int64_t a = std::max(prev->t_ns, t0), b = std::min(s.t_ns, t1);
    const Eigen::Vector3d w = 0.5 * (imu::interpolate(*prev, s, a).gyr + imu::interpolate(*prev, s, b).gyr) - bias;
    R = R * so3::exp(w * (static_cast<double>(b - a) * 1e-9));
    if (s.t_ns >= t1) return R;  // covered to the end
    prev = &s;
  }
  return std::nullopt;  // the samples end before t1
}

std::optional<Eigen::Matrix3d> GyroRotationPredictor::predict(const std::vector<ImuSample>& imu, int64_t t0,
                                                              int64_t t1, const Eigen::Vector3d& bias) const {
  const auto R_b = predict_body(imu, t0, t1, bias);
  if (!R_b) return std::nullopt;
  // p_b = R_bc p_c at both times, so the camera sees the body rotation conjugated by the extrinsic.
  return Eigen::Matrix3d(R_bc_.transpose() * *R_b * R_bc_);
}

}  // namespace dynavins::tracker
