#pragma once
// A scenario built from its spec: the body trajectory, the world with its moving objects, the
// stereo rig and the sensor noise; and ScenarioSource, which renders it into a time-ordered
// sensor stream (stereo frames with labels, 200 Hz IMU, ground truth) like any recording.

#include <memory>
#include <optional>

#include "io/sensor_source.hpp"
#include "io/vins_config_writer.hpp"
#include "sim/motion/imu_simulator.hpp"
#include "sim/motion/smooth_trajectory.hpp"
#include "sim/render/photometric.hpp"
#include "sim/render/renderer.hpp"
#include "sim/render/world.hpp"
#include "sim/scenario/scenario_spec.hpp"

namespace dynavins::sim {

/// Stereo camera rig on the body (IMU) frame.
struct StereoRig {
  CameraIntrinsics camera;         ///< both cameras (EuRoC cam0 by default)
  Eigen::Isometry3d T_body_cam0;   ///< camera z forward = body x, a few cm off the IMU, tilted slightly
  Eigen::Isometry3d T_body_cam1;   ///< cam0 moved `baseline` along its x axis
  double baseline = 0.11;          ///< [m]
  /// The project's standard rig (non-trivial extrinsics, EuRoC-like intrinsics, 0.11 m baseline).
  static StereoRig standard();
  /// VIODE's cameras on the same mount: 752x480 pinhole without distortion, fx = fy = 376, a 0.05 m
  /// baseline (a rig of other tools' scenes: half the stereo depth resolution of the standard one).
  static StereoRig viode();
  /// `euroc` (standard) or `viode`; throws std::runtime_error otherwise.
  static StereoRig preset(const std::string& name);
};

struct Scenario {
  ScenarioSpec spec;
  std::shared_ptr<const SmoothTrajectory> body;  ///< T_world_body(t), t from 0
  std::shared_ptr<const World> world;
  StereoRig rig;
  PhotometricOptions photometric;
  ImuSimulatorOptions imu;
  double duration = 0;       ///< rendered/IMU span [s]
  double frame_rate = 20.0;  ///< [Hz]
  int64_t epoch_ns = 0;      ///< added to every timestamp (sensor data looks like real recordings)
};

/// The body trajectory T_world_body(t) of a spec (cheap: no world, no rendering).
std::shared_ptr<const SmoothTrajectory> build_body_trajectory(const ScenarioSpec& spec);

/// Builds a scenario; `seed` / `duration` override the spec's when given. Generating the
/// world's textures dominates (seconds for a long street).
std::shared_ptr<const Scenario> build_scenario(const ScenarioSpec& spec, std::optional<uint64_t> seed = std::nullopt,
                                               std::optional<double> duration = std::nullopt);

/// The scenario's rig and IMU as a VINS-Fusion stereo-inertial config (what `sim --euroc` writes).
io::VinsStereoConfig vins_config(const Scenario& s);

/// The scenario as a recording: events in time order, frames rendered on demand.
class ScenarioSource final : public io::SensorSource {
 public:
  explicit ScenarioSource(std::shared_ptr<const Scenario> scenario);
  bool next(SensorEvent& out) override;
  double progress() const override;
  std::string describe() const override;

  /// Number of stereo frames the sequence holds.
  std::size_t frame_count() const { return frame_count_; }
  /// The views behind the last frame delivered: true depth and labels of both cameras.
  const RenderedView& last_left() const { return left_; }
  const RenderedView& last_right() const { return right_; }
  const Scenario& scenario() const { return *scenario_; }

 private:
  StereoFrame render_frame(std::size_t k);

  std::shared_ptr<const Scenario> scenario_;
  Renderer renderer_;
  ImuSimulation imu_;
  std::size_t frame_count_ = 0;
  std::size_t next_frame_ = 0, next_imu_ = 0, next_gt_ = 0;
  RenderedView left_, right_;
};

}  // namespace dynavins::sim
