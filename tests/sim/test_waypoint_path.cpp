// Scripted motion: geometric paths with rounded corners and a speed profile (car around a block, hand-held
// E-shaped walk, straight street drive, 3-D drone flight), and timed waypoints. The limits of the profile
// must hold on the final spline, i.e. on what the IMU will see.
#include <catch2/catch.hpp>

#include <cmath>

#include "stages/common/so3.hpp"
#include "sim/motion/waypoint_path.hpp"

using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

constexpr double kPi = 3.14159265358979323846;

PathWaypoint P(double x, double y, double z = 0.0) {
  PathWaypoint w;
  w.p = Eigen::Vector3d(x, y, z);
  return w;
}

struct Extremes {
  double v = 0, a = 0, w = 0, jerk = 0;
};

// Maxima over the whole trajectory, sampled at 200 Hz (the IMU rate).
Extremes extremes(const SmoothTrajectory& tr) {
  Extremes e;
  const long n = static_cast<long>(std::floor(tr.duration() * 200.0));
  for (long k = 0; k <= n; ++k) {
    const KinematicState s = tr.evaluate(tr.t_min() + k / 200.0);
    e.v = std::max(e.v, s.v_w.norm());
    e.a = std::max(e.a, s.a_w.norm());
    e.w = std::max(e.w, s.omega_b.norm());
    e.jerk = std::max(e.jerk, s.j_w.norm());
  }
  return e;
}

double closest_approach(const SmoothTrajectory& tr, const Eigen::Vector3d& p, double* t_at = nullptr) {
  double best = 1e9;
  for (double t = tr.t_min(); t <= tr.t_max(); t += 0.005) {
    const double d = (tr.position(t) - p).norm();
    if (d < best) {
      best = d;
      if (t_at) *t_at = t;
    }
  }
  return best;
}

// Margin for the spline fit on top of the dense path's limits: the fit follows the dense samples to
// microns (the report shows it); between samples its acceleration may differ by a percent or so.
constexpr double kFitMargin = 1.02;

}  // namespace

TEST_CASE("Car around a block respects speed, acceleration and yaw-rate limits", "[sim][waypoint_path]") {
  const PathProfile prof = PathProfile::car();
  const std::vector<PathWaypoint> wp{P(0, 0), P(60, 0), P(60, 40), P(0, 40), P(0, 0)};
  TrajectoryFitReport rep;
  const SmoothTrajectory tr = trajectory_from_path(wp, prof, &rep);
  const Extremes e = extremes(tr);
  INFO("duration " << tr.duration() << " s; max v " << e.v << " a " << e.a << " ω " << e.w << " jerk " << e.jerk
                   << "; fit residual " << rep.position_max << " m, " << rep.rotation_max << " rad");
  CHECK(rep.position_max < 1e-3);
  CHECK(rep.rotation_max < 1e-3);
  CHECK(e.v <= prof.cruise_speed * kFitMargin);
  CHECK(e.v > 0.95 * prof.cruise_speed);  // 60 m legs are long enough to reach cruise speed
  CHECK(e.a <= std::max(prof.max_lateral_acc, prof.max_longitudinal_acc) * kFitMargin);
  CHECK(e.w <= prof.max_yaw_rate * kFitMargin);
  // Smoothing turns acceleration steps (at most a_lat + a_lon) into ramps: jerk <= 2 Δa / smoothing_time.
  CHECK(e.jerk <= 2.0 * (prof.max_lateral_acc + prof.max_longitudinal_acc) / prof.smoothing_time * kFitMargin);

  // Starts and ends at rest, on the first / last waypoint, level and flat.
  for (double t : {0.0, 0.3, tr.t_max() - 0.3, tr.t_max()}) {
    CHECK(tr.velocity(t).norm() < 1e-3);
    CHECK(tr.angular_velocity(t).norm() < 1e-3);
  }
  CHECK((tr.position(0.0) - wp.front().p).norm() < 1e-3);
  CHECK((tr.position(tr.t_max()) - wp.back().p).norm() < 1e-3);
  for (double t = 0; t <= tr.t_max(); t += 0.5) {
    CHECK(std::abs(tr.position(t).z()) < 1e-6);
    CHECK(std::abs(tr.velocity(t).z()) < 1e-6);
    CHECK((tr.rotation(t) * Eigen::Vector3d::UnitZ()).z() > 1.0 - 1e-9);  // body z stays up
  }
  // Body x points along the velocity whenever the car moves.
  double worst = 0.0;
  for (double t = 0; t <= tr.t_max(); t += 0.1) {
    const Eigen::Vector3d v = tr.velocity(t);
    if (v.norm() < 1.0) continue;
    worst = std::max(worst, std::acos(std::clamp(v.normalized().dot(tr.rotation(t).col(0)), -1.0, 1.0)));
  }
  CHECK(worst < 0.02);
  // Corners are rounded but passed closely: a 90° arc of radius r misses the corner by (sqrt 2 - 1) r; the
  // smoothing filter cuts by about a τ^2 / 24 more, allowed twice.
  const double cut = (std::sqrt(2.0) - 1.0) * prof.corner_radius + prof.max_lateral_acc * prof.smoothing_time * prof.smoothing_time / 12.0;
  for (int i = 1; i <= 3; ++i) {
    const double d = closest_approach(tr, wp[i].p);
    INFO("corner " << i << " passed at " << d << " m");
    CHECK(d < cut);
    CHECK(d > 0.5 * (std::sqrt(2.0) - 1.0) * prof.corner_radius);  // and really rounded
  }
}

TEST_CASE("Hand-held E walk stops and turns in place at the prong ends", "[sim][waypoint_path]") {
  const PathProfile prof = PathProfile::handheld();
  // Spine from (0,0) up to (0,10); prongs to x = 4, 3, 4; each prong is walked out and back.
  const std::vector<PathWaypoint> wp{P(0, 0), P(4, 0), P(0, 0), P(0, 5), P(3, 5), P(0, 5), P(0, 10), P(4, 10)};
  const SmoothTrajectory tr = trajectory_from_path(wp, prof);
  const Extremes e = extremes(tr);
  INFO("duration " << tr.duration() << " s; max v " << e.v << " a " << e.a << " ω " << e.w << " jerk " << e.jerk);
  CHECK(e.a <= std::max(prof.max_lateral_acc, prof.max_longitudinal_acc) * kFitMargin);
  CHECK(e.w <= prof.max_yaw_rate * kFitMargin);
  CHECK(e.v <= prof.cruise_speed * kFitMargin);
  // Reversals (180°) are stops: the walker reaches the tip, stands, and turns round.
  for (int i : {1, 4}) {
    double t_tip = 0.0;
    const double d = closest_approach(tr, wp[i].p, &t_tip);
    INFO("prong tip " << i << " reached within " << d << " m at t = " << t_tip);
    CHECK(d < 1e-3);
    CHECK(tr.velocity(t_tip).norm() < 1e-3);
    // Heading half a second before arriving and after leaving differ by ~180°.
    double t0 = t_tip, t1 = t_tip;
    while (t0 > 0 && tr.velocity(t0).norm() < 0.2) t0 -= 0.01;
    while (t1 < tr.t_max() && tr.velocity(t1).norm() < 0.2) t1 += 0.01;
    const double turned = so3::log(tr.rotation(t0).transpose() * tr.rotation(t1)).norm();
    CHECK(turned == Approx(kPi).margin(0.05));
  }
  // The 90° corners into and out of the spine are rounded, not stops.
  for (int i : {3, 5}) {
    double t_c = 0.0;
    closest_approach(tr, wp[i].p, &t_c);
    CHECK(tr.velocity(t_c).norm() > 0.3);
  }
}

TEST_CASE("Straight street drive follows the trapezoidal speed profile", "[sim][waypoint_path]") {
  const PathProfile prof = PathProfile::car();
  const double L = 300.0;
  const SmoothTrajectory tr = trajectory_from_path({P(0, 0), P(L, 0)}, prof);
  const Extremes e = extremes(tr);
  // Rest, accelerate at a_lon to cruise, cruise, brake: L / v + v / a_lon, plus the dwells; the end dwell
  // is stretched by less than one sample to end on the sample grid.
  const double expected = prof.start_dwell + L / prof.cruise_speed + prof.cruise_speed / prof.max_longitudinal_acc + prof.end_dwell;
  CHECK(tr.duration() >= expected - 1e-9);
  CHECK(tr.duration() < expected + prof.sample_dt);
  CHECK(e.v == Approx(prof.cruise_speed).epsilon(1e-3));
  CHECK(e.a <= prof.max_longitudinal_acc * kFitMargin);
  CHECK(e.a > 0.95 * prof.max_longitudinal_acc);
  CHECK(e.w < 1e-9);  // no rotation at all
  CHECK((tr.position(tr.t_max()) - Eigen::Vector3d(L, 0, 0)).norm() < 1e-3);
  CHECK(tr.position(tr.t_max() / 2).y() == Approx(0.0).margin(1e-9));
}

TEST_CASE("Drone path in 3-D with scripted yaw, pitch and dwell", "[sim][waypoint_path]") {
  PathProfile prof = PathProfile::drone();
  prof.heading = HeadingMode::kWaypoints;
  std::vector<PathWaypoint> wp{P(0, 0, 1), P(5, 0, 1.5), P(5, 5, 2), P(0, 5, 1), P(0, 0, 1)};
  const double yaws[] = {0.0, 1.0, 3.0, -2.5, 0.3};  // -2.5 after 3.0: the shorter way is +0.78 rad
  for (size_t i = 0; i < wp.size(); ++i) wp[i].yaw = yaws[i];
  wp[2].pitch = 0.1;
  wp[2].dwell = 3.0;
  TrajectoryFitReport rep;
  const SmoothTrajectory tr = trajectory_from_path(wp, prof, &rep);
  const Extremes e = extremes(tr);
  INFO("duration " << tr.duration() << " s; max v " << e.v << " a " << e.a << " ω " << e.w);
  CHECK(e.a <= std::max(prof.max_lateral_acc, prof.max_longitudinal_acc) * kFitMargin);
  CHECK(e.w <= prof.max_yaw_rate * kFitMargin);
  // The dwell waypoint is a stop: reached exactly, held still, with its scripted attitude.
  double t2 = 0.0;
  CHECK(closest_approach(tr, wp[2].p, &t2) < 1e-3);
  double still = 0.0;
  for (double t = t2 - 5.0; t < t2 + 5.0; t += 0.01)
    if (t >= 0 && t <= tr.t_max() && tr.velocity(t).norm() < 1e-3 && (tr.position(t) - wp[2].p).norm() < 1e-3) still += 0.01;
  CHECK(still > 2.5);  // 3 s dwell, minus what the 0.6 s smoothing kernel blends into the approach/departure
  CHECK(so3::log(so3::from_yaw_pitch_roll(3.0, 0.1, 0.0).transpose() * tr.rotation(t2)).norm() < 0.01);
  // The end pose has the last yaw, reached the short way round (total yaw travel is bounded).
  CHECK(so3::log(so3::from_yaw_pitch_roll(0.3, 0.0, 0.0).transpose() * tr.rotation(tr.t_max())).norm() < 1e-3);
  double yaw_travel = 0.0;
  for (double t = 0.0; t + 0.01 <= tr.t_max(); t += 0.01) yaw_travel += std::abs(tr.angular_velocity(t).z()) * 0.01;
  CHECK(yaw_travel < 1.0 + 2.0 + 0.79 + 2.78 + 0.3);  // |Δyaw| per leg taken the short way, plus slack
}

TEST_CASE("Timed waypoints are interpolated through", "[sim][waypoint_path]") {
  std::vector<Waypoint> w;
  for (int i = 0; i <= 8; ++i) {
    Waypoint x;
    x.t = 1.5 * i;
    x.p = Eigen::Vector3d(std::cos(0.5 * i) * 3, std::sin(0.5 * i) * 3, 0.2 * i);
    x.yaw = 0.5 * i + kPi / 2;
    x.pitch = 0.05 * std::sin(double(i));
    x.roll = -0.05 * std::cos(double(i));
    w.push_back(x);
  }
  TrajectoryFitReport rep;
  const SmoothTrajectory tr = trajectory_from_timed_waypoints(w, default_script_fit_options(), &rep);
  CHECK(tr.t_min() == 0.0);
  CHECK(tr.t_max() == Approx(12.0));
  for (const Waypoint& x : w) {
    CHECK((tr.position(x.t) - x.p).norm() < 2e-3);
    CHECK(so3::log(so3::from_yaw_pitch_roll(x.yaw, x.pitch, x.roll).transpose() * tr.rotation(x.t)).norm() < 2e-3);
  }
  // A circle of radius 3 at 1/3 rad/s: centripetal 3 * (1/3)^2 = 0.33 m/s^2; the interpolant stays near it.
  CHECK(extremes(tr).a < 1.0);
}

TEST_CASE("Path input errors are reported", "[sim][waypoint_path]") {
  const PathProfile prof;
  CHECK_THROWS_WITH(densify_path({P(0, 0)}, prof), Catch::Contains("at least 2"));
  CHECK_THROWS_WITH(densify_path({P(0, 0), P(1, 0), P(1, 0)}, prof), Catch::Contains("waypoint 2") && Catch::Contains("coincides"));
  PathProfile wp_mode = prof;
  wp_mode.heading = HeadingMode::kWaypoints;
  CHECK_THROWS_WITH(densify_path({P(0, 0), P(1, 0)}, wp_mode), Catch::Contains("waypoint 0") && Catch::Contains("yaw"));
  std::vector<PathWaypoint> w{P(0, 0), P(1, 0)};
  w[1].dwell = -1.0;
  CHECK_THROWS_WITH(densify_path(w, prof), Catch::Contains("waypoint 1"));
  PathProfile bad = prof;
  bad.cruise_speed = 0.0;
  CHECK_THROWS_AS(densify_path({P(0, 0), P(1, 0)}, bad), std::invalid_argument);
  std::vector<Waypoint> tw(2);
  tw[1].t = 0.0;
  CHECK_THROWS_AS(trajectory_from_timed_waypoints(tw), std::invalid_argument);
}
