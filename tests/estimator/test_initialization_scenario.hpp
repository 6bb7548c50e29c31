#pragma once
// Synthetic ground truth shared by the initialisation tests: 1 s window of 11 frames at 10 Hz on a smooth
// 6-DoF motion (or a pure rotation), random landmarks 3-10 m in front of the middle camera projected on
// the cam0 normalized plane (optional pixel noise), 200 Hz IMU with a known gyroscope bias, preintegrated
// per frame interval with zero linearisation bias.
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "sim/motion/imu_simulator.hpp"
#include "sim/motion/waypoint_path.hpp"
#include "stages/estimator/initialization/mono_initializer.hpp"
#include "stages/imu/imu_preintegration.hpp"

namespace dynavins::estimator::test {

struct ScenarioOptions {
  bool pure_rotation = false;
  /// Straight line at 3 m/s, no acceleration (rotations as usual): the metric scale is not observable.
  bool constant_velocity = false;
  /// Straight line accelerating at a constant 1 m/s^2 from 1 m/s: the free gravity absorbs the
  /// acceleration, so the scale is not observable either.
  bool constant_acceleration = false;
  /// Feature ids i * 2^32 + 1 instead of i: all equal once truncated to 32 bits.
  bool wide_ids = false;
  double pixel_noise_px = 0.0;  ///< std of the observation noise [px] at focal 460
  bool imu_noise = false;       ///< EuRoC-grade white noise and bias walk
  Eigen::Vector3d gyro_bias = Eigen::Vector3d(0.02, -0.015, 0.025);
  int landmarks = 300;
  uint64_t seed = 7;
};

struct Scenario {
  static constexpr double kFocal = 460.0;
  sim::SmoothTrajectory traj;
  std::vector<double> t;                   ///< frame times [s]
  std::vector<sim::KinematicState> truth;  ///< body truth per frame
  Eigen::Matrix3d R_bc;
  Eigen::Vector3d p_bc;
  std::map<FeatureId, Eigen::Vector3d> landmarks_w;
  std::vector<FrameFeatures> features;
  std::vector<std::unique_ptr<imu::ImuPreintegration>> preints;  ///< frame k -> k+1

  int frames() const { return static_cast<int>(t.size()); }
  Eigen::Matrix3d R_wc(int k) const { return truth[k].R_wb * R_bc; }
  Eigen::Vector3d p_wc(int k) const { return truth[k].p_w + truth[k].R_wb * p_bc; }
  std::vector<const imu::ImuPreintegration*> preint_pointers() const {
    std::vector<const imu::ImuPreintegration*> v;
    for (const auto& p : preints) v.push_back(p.get());
    return v;
  }
  /// The initializer's input (pointers into this scenario's preintegrations).
  std::vector<InitWindowFrame> window() const {
    std::vector<InitWindowFrame> w(t.size());
    for (size_t k = 0; k < t.size(); ++k) {
      w[k].t = t[k];
      w[k].features = features[k];
      w[k].preint = k == 0 ? nullptr : preints[k - 1].get();
    }
    return w;
  }
};

inline sim::SmoothTrajectory scenario_trajectory(bool pure_rotation, bool constant_velocity = false,
                                                bool constant_acceleration = false) {
  std::vector<sim::Waypoint> w;
  for (int i = 0; i <= 12; ++i) {
    const double t = 0.25 * i;
    sim::Waypoint p;
    p.t = t;
    if (constant_velocity)
      p.p = Eigen::Vector3d(3.0 * t, 0.0, 0.0);
    else if (constant_acceleration)
      p.p = Eigen::Vector3d(1.0 * t + 0.5 * t * t, 0.0, 0.0);
    else if (!pure_rotation)
      p.p = Eigen::Vector3d(0.8 * t + 0.3 * std::sin(3.0 * t), 0.4 * std::sin(2.2 * t), 0.25 * std::sin(2.7 * t));
    p.yaw = 0.4 * std::sin(1.3 * t);
    p.pitch = 0.15 * std::sin(1.7 * t);
    p.roll = 0.1 * std::cos(1.9 * t);
    w.push_back(p);
  }
  return sim::trajectory_from_timed_waypoints(w);
}

inline Scenario make_scenario(const ScenarioOptions& o = {}) {
  Scenario s;
  s.traj = scenario_trajectory(o.pure_rotation, o.constant_velocity, o.constant_acceleration);
  // Camera looking along body x (body x forward, y left, z up; camera z forward, x right, y down).
  s.R_bc << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  s.p_bc = Eigen::Vector3d(0.05, 0.02, -0.01);
  const int64_t t0_ns = 1'000'000'000, dt_ns = 100'000'000;
  const int n = 11;
  for (int k = 0; k < n; ++k) {
    s.t.push_back((t0_ns + k * dt_ns) * 1e-9);
    s.truth.push_back(s.traj.evaluate(s.t.back()));
  }
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(3.0, 10.0);
  std::normal_distribution<double> noise(0.0, o.pixel_noise_px / Scenario::kFocal);
  const int mid = n / 2;
  for (int i = 0; i < o.landmarks; ++i) {
    const double z = depth(rng);
    const Eigen::Vector3d p_c(0.8 * u(rng) * z, 0.6 * u(rng) * z, z);
    const FeatureId id = o.wide_ids ? (static_cast<FeatureId>(i) << 32) + 1 : i;
    s.landmarks_w[id] = s.R_wc(mid) * p_c + s.p_wc(mid);
  }
  s.features.resize(n);
  for (int k = 0; k < n; ++k)
    for (const auto& [id, pw] : s.landmarks_w) {
      const Eigen::Vector3d p_c = s.R_wc(k).transpose() * (pw - s.p_wc(k));
      if (p_c.z() < 0.5) continue;
      const Eigen::Vector2d x = p_c.head<2>() / p_c.z();
      if (std::abs(x.x()) > 0.82 || std::abs(x.y()) > 0.65) continue;  // 752x480 image at f = 460
      s.features[k][id] = x + Eigen::Vector2d(noise(rng), noise(rng));
    }

  sim::ImuSimulatorOptions io;
  io.rate_hz = 200.0;
  io.noise = o.imu_noise ? sim::ImuNoiseModel{} : sim::ImuNoiseModel::noise_free();
  io.noise.acc_bias_initial.setZero();
  io.noise.gyr_bias_initial = o.gyro_bias;
  io.seed = o.seed;
  const sim::ImuSimulation imu = sim::ImuSimulator(io).simulate(s.traj, t0_ns, t0_ns + (n - 1) * dt_ns);
  for (int k = 0; k + 1 < n; ++k) {
    const int64_t a = t0_ns + k * dt_ns, b = a + dt_ns;
    std::unique_ptr<imu::ImuPreintegration> pre;
    for (const ImuSample& smp : imu.samples) {
      if (smp.t_ns < a || smp.t_ns > b) continue;
      if (!pre) pre = std::make_unique<imu::ImuPreintegration>(smp, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                          imu::ImuNoiseParams{});
      else pre->integrate(smp);
    }
    s.preints.push_back(std::move(pre));
  }
  return s;
}

/// Angle of a rotation matrix [deg].
inline double angle_deg(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle() * 180.0 / M_PI; }

}  // namespace dynavins::estimator::test
