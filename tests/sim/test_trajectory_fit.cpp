// fit_trajectory: exact recovery of a spline from its own samples, noise suppression at the level the
// noise model predicts, and rejection of bad input.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "stages/common/so3.hpp"
#include "sim/motion/trajectory_fit.hpp"

using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

// A smooth, lively reference motion (about 1 m/s, 1 rad/s) as a spline with knot spacing 0.05 s.
SmoothTrajectory reference_trajectory() {
  const double dt = 0.05;
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Matrix3d> r;
  for (int k = 0; k < 203; ++k) {
    const double t = (k - 1) * dt;
    p.emplace_back(2.0 * std::sin(0.5 * t), 1.5 * std::sin(0.8 * t + 1.0), 0.3 * std::sin(1.3 * t));
    r.push_back(so3::exp(Eigen::Vector3d(0.3 * std::sin(1.1 * t), 0.2 * std::cos(0.7 * t), 0.9 * t)));
  }
  return SmoothTrajectory(BSplineR3(0.0, dt, p), BSplineSO3(0.0, dt, r));
}

std::vector<TimedPose> sample(const SmoothTrajectory& tr, double rate) {
  std::vector<TimedPose> out;
  const int n = static_cast<int>(std::floor(tr.duration() * rate + 1e-9));
  for (int m = 0; m <= n; ++m) {
    const double t = tr.t_min() + m / rate;
    out.push_back({t, tr.position(t), tr.orientation(t)});
  }
  return out;
}

}  // namespace

TEST_CASE("fit_trajectory recovers a spline from its own exact samples", "[sim][trajectory_fit]") {
  const SmoothTrajectory ref = reference_trajectory();
  const std::vector<TimedPose> data = sample(ref, 200.0);
  TrajectoryFitReport rep;
  const SmoothTrajectory fit = fit_trajectory(data, {}, &rep);  // defaults: same 0.05 s knots
  CHECK(rep.knot_spacing == Approx(0.05).epsilon(1e-12));
  CHECK(rep.converged);
  INFO("residual pos " << rep.position_rms << " m, rot " << rep.rotation_rms << " rad, GN iterations "
                       << rep.gauss_newton_iterations);
  // Interior and the first/last 0.2 s apart: at the ends only one side holds data, so the prior has more say.
  double ea = 0.0, ew = 0.0, ea_end = 0.0, ew_end = 0.0;
  for (double t = 0.0; t <= ref.t_max(); t += 0.01) {
    const double e_a = (fit.acceleration(t) - ref.acceleration(t)).norm();
    const double e_w = (fit.angular_velocity(t) - ref.angular_velocity(t)).norm();
    const bool end = t < 0.2 || t > ref.t_max() - 0.2;
    (end ? ea_end : ea) = std::max(end ? ea_end : ea, e_a);
    (end ? ew_end : ew) = std::max(end ? ew_end : ew, e_w);
  }
  INFO("max acceleration error " << ea << " m/s^2 (ends " << ea_end << "), max angular velocity error " << ew
                                 << " rad/s (ends " << ew_end << ")");
  // The truth lies in the model, so only the light prior pulls the fit off it.
  CHECK(rep.position_max < 1e-5);
  CHECK(rep.rotation_max < 1e-5);
  CHECK(ea < 1e-3);
  CHECK(ew < 1e-4);
  CHECK(ea_end < 0.05);
  CHECK(ew_end < 1e-3);
  CHECK(rep.gauss_newton_iterations <= 6);
}

TEST_CASE("fit_trajectory averages measurement noise instead of following it", "[sim][trajectory_fit]") {
  const SmoothTrajectory ref = reference_trajectory();
  std::vector<TimedPose> data = sample(ref, 200.0);
  const double sp = 1e-3, sr = 2e-3;  // the default noise model of the fit
  std::mt19937_64 rng(99);
  std::normal_distribution<double> n01(0.0, 1.0);
  for (TimedPose& s : data) {
    s.p += sp * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    s.q = Eigen::Quaterniond(s.q.toRotationMatrix() * so3::exp(sr * Eigen::Vector3d(n01(rng), n01(rng), n01(rng))));
  }
  TrajectoryFitReport rep;
  const SmoothTrajectory fit = fit_trajectory(data, {}, &rep);
  TrajectoryFitOptions wide;
  wide.knot_spacing = 0.2;
  const SmoothTrajectory fit_wide = fit_trajectory(data, wide);
  double ep = 0, er = 0, ea = 0, ew = 0, ea_wide = 0, ew_wide = 0;
  int n = 0;
  for (const TimedPose& s : data) {
    ep += (fit.position(s.t) - ref.position(s.t)).squaredNorm();
    er += so3::log(fit.rotation(s.t).transpose() * ref.rotation(s.t)).squaredNorm();
    ea += (fit.acceleration(s.t) - ref.acceleration(s.t)).squaredNorm();
    ew += (fit.angular_velocity(s.t) - ref.angular_velocity(s.t)).squaredNorm();
    ea_wide += (fit_wide.acceleration(s.t) - ref.acceleration(s.t)).squaredNorm();
    ew_wide += (fit_wide.angular_velocity(s.t) - ref.angular_velocity(s.t)).squaredNorm();
    ++n;
  }
  ep = std::sqrt(ep / n);
  er = std::sqrt(er / n);
  ea = std::sqrt(ea / n);
  ew = std::sqrt(ew / n);
  ea_wide = std::sqrt(ea_wide / n);
  ew_wide = std::sqrt(ew_wide / n);
  INFO("residual to data: pos " << rep.position_rms << " rot " << rep.rotation_rms << "; error to truth: pos " << ep
                                << " rot " << er << " acc " << ea << " ω " << ew << "; with 0.2 s knots: acc "
                                << ea_wide << " ω " << ew_wide);
  // 3-D noise has RMS norm sqrt(3) σ. A least-squares fit with p parameters per axis to n samples leaves
  // sqrt(1 - p/n) of it as residual; here p/n = 1/10 (200 Hz, 0.05 s knots). 3 % ~ 3 standard errors of
  // an RMS over 6000 values; a fit that follows the noise or misses the motion lands outside.
  const double keep = std::sqrt(3.0 * (1.0 - double(rep.num_control_points) / rep.num_samples));
  CHECK(rep.position_rms == Approx(keep * sp).epsilon(0.03));
  CHECK(rep.rotation_rms == Approx(keep * sr).epsilon(0.03));
  // About 10 samples per knot are averaged, so the error to the truth is well below the noise.
  CHECK(ep < 0.5 * std::sqrt(3.0) * sp);
  CHECK(er < 0.5 * std::sqrt(3.0) * sr);
  // Differentiating twice amplifies noise: 1 mm white noise at 200 Hz through 0.05 s knots leaves about
  // 1 m/s^2 of acceleration noise (the figure quoted in TrajectoryFitOptions; a 30 % band around it).
  CHECK(ea == Approx(1.1).epsilon(0.3));
  // Wider knots are the remedy: the acceleration noise falls as dt^-2.5 (32x for 4x the spacing), so
  // with 0.2 s knots it is below 0.1 m/s^2, ~1 % of g, and ω is accurate to 0.02 rad/s.
  CHECK(ea_wide < 0.1);
  CHECK(ew_wide < 0.02);
}

TEST_CASE("fit_trajectory fills sparse samples with the minimum-jerk curve", "[sim][trajectory_fit]") {
  // Three poses 2 s apart. The jerk prior's minimiser through three points is the quadratic through them
  // (zero jerk, zero residual; a cubic B-spline represents it exactly): x = t, y = t - t^2/4, z = t(t-2)/8,
  // so a = (0, -0.5, 0.25) throughout; the yaw 0, 1, 2 rad is linear in time: ω = (0, 0, 0.5), α = 0.
  std::vector<TimedPose> data{{0.0, Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity()},
                              {2.0, Eigen::Vector3d(2, 1, 0), Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0, 0, 1)))},
                              {4.0, Eigen::Vector3d(4, 0, 1), Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0, 0, 2)))}};
  TrajectoryFitReport rep;
  const SmoothTrajectory fit = fit_trajectory(data, {}, &rep);
  CHECK(rep.position_max < 1e-9);
  CHECK(rep.rotation_max < 1e-9);
  for (double t = 0; t <= 4.0; t += 0.01) {
    const KinematicState s = fit.evaluate(t);
    // (between the samples only three points pin 83 control points: the solve is good to ~1e-7 m)
    CHECK((s.p_w - Eigen::Vector3d(t, t - t * t / 4, t * (t - 2) / 8)).norm() < 1e-6);
    CHECK((s.a_w - Eigen::Vector3d(0, -0.5, 0.25)).norm() < 1e-6);
    CHECK((s.omega_b - Eigen::Vector3d(0, 0, 0.5)).norm() < 1e-6);
    CHECK(s.alpha_b.norm() < 1e-5);
  }
}

TEST_CASE("fit_trajectory rejects bad input with the offending index", "[sim][trajectory_fit]") {
  const TimedPose a{0.0, Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity()};
  CHECK_THROWS_AS(fit_trajectory({a}), std::invalid_argument);
  TimedPose b = a;
  b.t = 0.0;
  CHECK_THROWS_WITH(fit_trajectory({a, b}), Catch::Contains("pose 1") && Catch::Contains("increasing"));
  b.t = 0.1;
  b.q = Eigen::Quaterniond(0.5, 0.5, 0.5, 0.6);
  CHECK_THROWS_WITH(fit_trajectory({a, b}), Catch::Contains("unit"));
  b.q = Eigen::Quaterniond(so3::exp(Eigen::Vector3d(0, 0, 3.0)));
  CHECK_THROWS_WITH(fit_trajectory({a, b}), Catch::Contains("ambiguous"));
  b.q.setIdentity();
  b.p.x() = std::nan("");
  CHECK_THROWS_WITH(fit_trajectory({a, b}), Catch::Contains("non-finite"));
  b.p.x() = 0.0;
  TrajectoryFitOptions o;
  o.knot_spacing = 0.0;
  CHECK_THROWS_AS(fit_trajectory({a, b}, o), std::invalid_argument);
}
