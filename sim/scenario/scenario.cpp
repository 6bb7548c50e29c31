#include "sim/scenario/scenario.hpp"

#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "sim/motion/tum_trajectory.hpp"
#include "sim/motion/waypoint_path.hpp"
#include "sim/render/street_scene.hpp"

namespace dynavins::sim {
namespace {

constexpr int64_t kEpochNs = 1'700'000'000'000'000'000;  // a whole number of microseconds

/// Heading (yaw of body x in the world) of the rig at time t, and its ground position.
struct GroundPose {
  Eigen::Vector2d xy;
  double yaw;
};
GroundPose ground_pose(const SmoothTrajectory& body, double t) {
  t = std::clamp(t, body.t_min(), body.t_max());
  const Eigen::Isometry3d T = body.pose(t);
  const Eigen::Vector3d fwd = T.linear().col(0);
  return {T.translation().head<2>(), std::atan2(fwd.y(), fwd.x())};
}

Eigen::Isometry3d on_ground(const Eigen::Vector2d& xy, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(Eigen::Vector3d(xy.x(), xy.y(), 0.0));
  T.rotate(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
  return T;
}

/// The pose function of one moving object (object frame: centre of its bottom face, x along its length).
PoseFunction object_motion(const MovingObjectSpec& o, std::shared_ptr<const SmoothTrajectory> body) {
  switch (o.motion) {
    case ObjectMotion::Lane:
      return [o](double t) {
        return on_ground({o.x0 + o.speed * (t - o.t0), o.y}, o.speed >= 0 ? 0.0 : M_PI);
      };
    case ObjectMotion::CrossAhead: {
      // Where the rig will be at o.t, and `distance` ahead of it: the crossing point.
      const GroundPose g = ground_pose(*body, o.t);
      const Eigen::Vector2d heading(std::cos(g.yaw), std::sin(g.yaw));
      const Eigen::Vector2d left(-heading.y(), heading.x());
      const Eigen::Vector2d centre = g.xy + o.distance * heading;
      const double yaw = g.yaw + (o.speed >= 0 ? M_PI_2 : -M_PI_2);
      return [o, centre, left, yaw](double t) { return on_ground(centre + o.speed * (t - o.t) * left, yaw); };
    }
    case ObjectMotion::Follow:
      return [o, body](double t) {
        const GroundPose g = ground_pose(*body, t);
        const Eigen::Vector2d heading(std::cos(g.yaw), std::sin(g.yaw));
        const Eigen::Vector2d left(-heading.y(), heading.x());
        return on_ground(g.xy + o.distance * heading + o.offset * left, g.yaw);
      };
    case ObjectMotion::Relocate:
      return [o](double t) {
        std::size_t i = 0;
        while (i + 1 < o.poses.size() && t >= o.poses[i + 1][0]) ++i;
        const Eigen::Vector4d& p = o.poses[i];
        return on_ground({p[1], p[2]}, p[3] * M_PI / 180.0);
      };
  }
  throw std::logic_error("unknown object motion");
}

PathProfile profile_of(const ScenarioSpec& s) {
  PathProfile p = s.profile == "car" ? PathProfile::car() : s.profile == "handheld" ? PathProfile::handheld()
                                                                                   : PathProfile::drone();
  if (s.cruise_speed > 0) p.cruise_speed = s.cruise_speed;
  return p;
}

/// cam1 = cam0 moved `baseline` along cam0's x axis.
void place_cam1(StereoRig& rig) {
  Eigen::Isometry3d T_cam0_cam1 = Eigen::Isometry3d::Identity();
  T_cam0_cam1.translation() = Eigen::Vector3d(rig.baseline, 0, 0);
  rig.T_body_cam1 = rig.T_body_cam0 * T_cam0_cam1;
}

}  // namespace

StereoRig StereoRig::standard() {
  StereoRig rig;
  // Camera axes in the body frame (x forward, y left, z up): camera x right = -y, y down = -z,
  // z forward = x; then a small misalignment so the extrinsics are not a permutation.
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(-0.015, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()))
                                   .toRotationMatrix();
  rig.T_body_cam0 = Eigen::Isometry3d::Identity();
  rig.T_body_cam0.linear() = R * tilt;
  rig.T_body_cam0.translation() = Eigen::Vector3d(0.06, 0.03, -0.02);
  place_cam1(rig);
  return rig;
}

StereoRig StereoRig::viode() {
  StereoRig rig = standard();
  rig.camera = CameraIntrinsics{752, 480, 376.0, 376.0, 376.0, 240.0, 0.0, 0.0, 0.0, 0.0};
  rig.baseline = 0.05;
  place_cam1(rig);
  return rig;
}

StereoRig StereoRig::preset(const std::string& name) {
  if (name == "euroc") return standard();
  if (name == "viode") return viode();
  throw std::runtime_error("unknown rig '" + name + "' (euroc | viode)");
}

namespace {

/// Recorded motion (motion.tum): the file's window fitted, its world turned by the placement's yaw and
/// moved to its x, y, z, the body axes renamed so the rig's camera looks where the recorded one did.
std::shared_ptr<const SmoothTrajectory> build_recorded_trajectory(const ScenarioSpec& spec) {
  TumFitOptions o;
  o.window_start = spec.tum_start;
  o.window_duration = spec.duration > 0 ? spec.duration + 1.0 : 0.0;  // a little past the sequence's end
  const Eigen::Vector4d& pl = spec.tum_placement;
  o.world_from_file.linear() = Eigen::AngleAxisd(pl[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  o.world_from_file.translation() = pl.head<3>();
  if (spec.tum_body_axes == "euroc") {
    // EuRoC's cam0 looks along the IMU's z, its x along the IMU's y, its y along the IMU's -x; our rig's
    // camera looks along body x with x = -y_body, y = -z_body. Columns: our body axes in the IMU's frame.
    o.file_body_from_body << 0, 0, 1,  //
        0, -1, 0,                       //
        1, 0, 0;
  }
  try {
    TumFitReport report;
    auto traj = std::make_shared<SmoothTrajectory>(fit_tum_trajectory(spec.tum_file, o, &report));
    spdlog::info("{}: fitted {} poses of {} (from {:.1f} s), RMS {:.1f} mm / {:.2f} deg", spec.file,
                 report.fit.num_samples, spec.tum_file, spec.tum_start, report.fit.position_rms * 1e3,
                 report.fit.rotation_rms * 180.0 / M_PI);
    return traj;
  } catch (const std::exception& e) {
    throw std::runtime_error(spec.file + ": motion.tum: " + e.what());
  }
}

}  // namespace

std::shared_ptr<const SmoothTrajectory> build_body_trajectory(const ScenarioSpec& spec) {
  if (!spec.tum_file.empty()) return build_recorded_trajectory(spec);
  std::vector<PathWaypoint> corners;
  for (std::size_t i = 0; i < spec.waypoints.size(); ++i) {
    PathWaypoint p;
    p.p = spec.waypoints[i];
    if (i < spec.dwell.size()) p.dwell = spec.dwell[i];
    corners.push_back(p);
  }
  try {
    return std::make_shared<SmoothTrajectory>(trajectory_from_path(corners, profile_of(spec)));
  } catch (const std::exception& e) {
    throw std::runtime_error(spec.file + ": motion.waypoints: " + e.what());
  }
}

std::shared_ptr<const Scenario> build_scenario(const ScenarioSpec& spec, std::optional<uint64_t> seed,
                                               std::optional<double> duration) {
  auto s = std::make_shared<Scenario>();
  s->spec = spec;
  if (seed) s->spec.seed = *seed;
  s->body = build_body_trajectory(spec);
  const double path_s = s->body->t_max() - s->body->t_min();
  s->duration = std::min(path_s, duration.value_or(spec.duration > 0 ? spec.duration : path_s));
  if (duration && *duration > path_s)
    spdlog::warn("{}: the path lasts {:.1f} s; the sequence is that long, not {:.1f} s", spec.file, path_s, *duration);

  StreetSceneOptions street;
  street.seed = spec.world_seed;
  street.x_min = spec.world_x_min;
  street.x_max = spec.world_x_max;
  street.avenue_y = spec.avenue_y;
  street.cross_street_x = spec.cross_street_x;
  street.moving_vehicles = false;
  auto world = std::make_shared<World>(make_street_scene(street));
  uint64_t texture_seed = s->spec.seed * 1000;
  for (const auto& o : spec.objects) {
    const PoseFunction pose = object_motion(o, s->body);
    if (o.kind == ObjectKind::Truck) world->add_truck(pose, ++texture_seed);
    else if (o.kind == ObjectKind::Car) world->add_car(pose, ++texture_seed);
    else  // a feature-rich board (poster-like truck-side texture), 2.4 m wide, 1.8 m tall
      world->add_moving_box(Eigen::Vector3d(0.12, 2.4, 1.8), pose, ++texture_seed, BoxStyle::Truck, "board");
  }
  s->world = world;
  s->rig = StereoRig::preset(spec.rig);
  s->photometric = spec.photometric == "night" ? PhotometricOptions::night() : PhotometricOptions{};
  s->photometric.seed = s->spec.seed;
  s->imu.seed = s->spec.seed;
  // Non-zero initial biases, of the size real MEMS IMUs start with (EuRoC V1_01: ~0.1 m/s^2, ~0.01 rad/s).
  s->imu.noise.acc_bias_initial = Eigen::Vector3d(-0.08, 0.12, 0.05);
  s->imu.noise.gyr_bias_initial = Eigen::Vector3d(0.004, -0.012, 0.008);
  s->epoch_ns = kEpochNs;
  return s;
}

ScenarioSource::ScenarioSource(std::shared_ptr<const Scenario> scenario)
    : scenario_(std::move(scenario)), renderer_(scenario_->rig.camera) {
  const Scenario& s = *scenario_;
  const auto t0_ns = static_cast<int64_t>(std::ceil(s.body->t_min() * 1e9));
  const auto t1_ns = t0_ns + static_cast<int64_t>(s.duration * 1e9);
  imu_ = ImuSimulator(s.imu).simulate(*s.body, t0_ns, t1_ns);
  frame_count_ = static_cast<std::size_t>(std::floor(s.duration * s.frame_rate + 1e-9)) + 1;
}

StereoFrame ScenarioSource::render_frame(std::size_t k) {
  const Scenario& s = *scenario_;
  const double t = s.body->t_min() + static_cast<double>(k) / s.frame_rate;
  const Eigen::Isometry3d T_wb = s.body->pose(t);
  std::tie(left_, right_) = renderer_.render_stereo(*s.world, t, T_wb * s.rig.T_body_cam0,
                                                    s.rig.T_body_cam0.inverse() * s.rig.T_body_cam1);
  StereoFrame f;
  f.t_ns = s.epoch_ns + static_cast<int64_t>(std::llround(t * 1e9));
  f.seq = static_cast<int64_t>(k);
  f.left = apply_photometric(left_.gray, s.photometric, t, 0);
  f.right = apply_photometric(right_.gray, s.photometric, t, 1);
  f.labels = left_.labels;
  return f;
}

bool ScenarioSource::next(SensorEvent& out) {
  const Scenario& s = *scenario_;
  constexpr int64_t kNone = INT64_MAX;
  const int64_t tf = next_frame_ < frame_count_
                         ? s.epoch_ns + static_cast<int64_t>(std::llround(
                                            (s.body->t_min() + static_cast<double>(next_frame_) / s.frame_rate) * 1e9))
                         : kNone;
  const int64_t ti = next_imu_ < imu_.samples.size() ? s.epoch_ns + imu_.samples[next_imu_].t_ns : kNone;
  const int64_t tg = next_gt_ < imu_.truth.size() ? s.epoch_ns + imu_.truth[next_gt_].t_ns : kNone;
  if (tf == kNone && ti == kNone && tg == kNone) return false;
  if (ti <= tf && ti <= tg) {  // IMU first at equal times, as a real driver would deliver it
    ImuSample m = imu_.samples[next_imu_++];
    m.t_ns += s.epoch_ns;
    out = m;
  } else if (tg <= tf) {
    GroundTruthState g = imu_.truth[next_gt_++];
    g.t_ns += s.epoch_ns;
    out = g;
  } else {
    out = render_frame(next_frame_++);
  }
  return true;
}

double ScenarioSource::progress() const {
  return static_cast<double>(next_frame_) / static_cast<double>(frame_count_);
}

std::string ScenarioSource::describe() const {
  return scenario_->spec.name + " (simulated, seed " + std::to_string(scenario_->spec.seed) + ", " +
         std::to_string(frame_count_) + " stereo frames)";
}

io::VinsStereoConfig vins_config(const Scenario& s) {
  io::VinsStereoConfig c;
  const auto& k = s.rig.camera;
  c.cam0 = {k.width, k.height, k.fx, k.fy, k.cx, k.cy, k.k1, k.k2, k.p1, k.p2};
  c.cam1 = c.cam0;
  c.body_T_cam0 = s.rig.T_body_cam0;
  c.body_T_cam1 = s.rig.T_body_cam1;
  c.g_norm = s.imu.gravity;
  return c;
}

}  // namespace dynavins::sim
