// ImuSimulator: exact kinematics (integrating the noise-free IMU reproduces the trajectory), the noise
// model's statistics, bias bookkeeping in the ground truth, timestamps and determinism.
#include <catch2/catch.hpp>

#include <cmath>

#include "sim/motion/imu_simulator.hpp"
#include "stages/common/so3.hpp"
#include "sim/motion/tum_trajectory.hpp"
#include "sim/motion/waypoint_path.hpp"

using namespace dynavins::sim;
namespace so3 = dynavins::so3;
using dynavins::GroundTruthState;
using dynavins::ImuSample;

namespace {

// A body standing still for `duration` seconds with a fixed, tilted orientation.
SmoothTrajectory still(double duration, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity(),
                       const Eigen::Vector3d& p = Eigen::Vector3d(1, 2, 3)) {
  const int n = static_cast<int>(std::ceil(duration / 0.1)) + 3;
  return SmoothTrajectory(BSplineR3(0.0, duration / (n - 3), std::vector<Eigen::Vector3d>(n, p)),
                          BSplineSO3(0.0, duration / (n - 3), std::vector<Eigen::Matrix3d>(n, R)));
}

PathWaypoint wp(double x, double y, double z) {
  PathWaypoint w;
  w.p = Eigen::Vector3d(x, y, z);
  return w;
}

struct State {
  Eigen::Quaterniond q;
  Eigen::Vector3d p, v;
};

// Classical RK4 on (q, p, v) with q' = q (0, ω/2), p' = v, v' = R a + g. A step spans two IMU samples so
// that the half-step stages use the middle sample (no interpolation error).
State integrate_rk4(const State& x0, const std::vector<ImuSample>& imu, size_t first, size_t steps, double g) {
  const Eigen::Vector3d gw(0, 0, -g);
  struct D {
    Eigen::Vector4d dq;
    Eigen::Vector3d dp, dv;
  };
  auto deriv = [&](const Eigen::Quaterniond& q, const Eigen::Vector3d& v, const ImuSample& m) {
    const Eigen::Quaterniond w(0.0, 0.5 * m.gyr.x(), 0.5 * m.gyr.y(), 0.5 * m.gyr.z());
    return D{(q * w).coeffs(), v, q.normalized().toRotationMatrix() * m.acc + gw};
  };
  auto add = [](const State& x, const D& d, double h) {
    State y;
    y.q.coeffs() = x.q.coeffs() + h * d.dq;
    y.p = x.p + h * d.dp;
    y.v = x.v + h * d.dv;
    return y;
  };
  State x = x0;
  for (size_t s = 0; s < steps; ++s) {
    const ImuSample& m0 = imu[first + 2 * s];
    const ImuSample& m1 = imu[first + 2 * s + 1];
    const ImuSample& m2 = imu[first + 2 * s + 2];
    const double h = (m2.t_ns - m0.t_ns) * 1e-9;
    const D k1 = deriv(x.q, x.v, m0);
    const State x2 = add(x, k1, h / 2);
    const D k2 = deriv(x2.q, x2.v, m1);
    const State x3 = add(x, k2, h / 2);
    const D k3 = deriv(x3.q, x3.v, m1);
    const State x4 = add(x, k3, h);
    const D k4 = deriv(x4.q, x4.v, m2);
    x.q.coeffs() += h / 6 * (k1.dq + 2 * k2.dq + 2 * k3.dq + k4.dq);
    x.q.normalize();
    x.p += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    x.v += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
  }
  return x;
}

struct Drift {
  double pos = 0, rot = 0, vel = 0;
};

// Integrates the noise-free IMU of [t0, t0 + 10 s] from the true state at t0 and compares with the truth
// at every step.
Drift drift10s(const SmoothTrajectory& tr, double t0, double g = 9.81, double gyro_scale = 1.0) {
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  o.gravity = g;
  const ImuSimulator sim(o);
  const auto t0_ns = static_cast<int64_t>(std::llround(t0 * 1e9));
  ImuSimulation s = sim.simulate(tr, t0_ns, t0_ns + 10'000'000'000LL);
  REQUIRE(s.samples.size() == 2001);
  for (ImuSample& m : s.samples) m.gyr *= gyro_scale;
  const GroundTruthState& g0 = s.truth.front();
  State x{g0.q_wb, g0.p_wb, g0.v_wb};
  Drift d;
  for (size_t k = 0; k + 2 < s.samples.size(); k += 2) {
    x = integrate_rk4(x, s.samples, k, 1, g);
    const GroundTruthState& gt = s.truth[k + 2];
    d.pos = std::max(d.pos, (x.p - gt.p_wb).norm());
    d.vel = std::max(d.vel, (x.v - gt.v_wb).norm());
    d.rot = std::max(d.rot, x.q.angularDistance(gt.q_wb));
  }
  return d;
}

double path_length(const SmoothTrajectory& tr, double t0, double t1) {
  double L = 0;
  for (double t = t0; t < t1; t += 0.01) L += tr.velocity(t).norm() * 0.01;
  return L;
}

}  // namespace

TEST_CASE("Noise-free IMU integrates back to the scripted trajectory (< 1 cm in 10 s)", "[sim][imu_simulator]") {
  // Hand-held E walk, a 10 s stretch with a rounded corner, a stop and a turn in place.
  const SmoothTrajectory tr = trajectory_from_path(
      {wp(0, 0, 0), wp(0, 5, 0),
       wp(3, 5, 0.5), wp(0, 5, 0),
       wp(0, 10, 0)},
      PathProfile::handheld());
  REQUIRE(tr.duration() > 16.0);
  for (double t0 : {0.0, 3.0, 6.0}) {
    const Drift d = drift10s(tr, t0);
    INFO("scripted, start " << t0 << " s, path " << path_length(tr, t0, t0 + 10) << " m: max drift pos " << d.pos
                            << " m, vel " << d.vel << " m/s, rot " << d.rot << " rad");
    CHECK(d.pos < 0.01);
    CHECK(d.rot < 1e-4);
  }
}

TEST_CASE("Noise-free IMU integrates back to a real EuRoC trajectory (< 1 cm in 10 s)", "[sim][imu_simulator]") {
  // V1_03_difficult: fast, aggressive flight in the Vicon room (up to ~1.5 m/s and ~2 rad/s).
  TumFitOptions o;
  o.window_start = 20.0;
  o.window_duration = 31.0;
  const SmoothTrajectory tr = fit_tum_trajectory(std::string(DYNAVINS_SHARED_DIR) + "/data/trajectories/euroc_tum/V1_03_difficult.txt.gz", o);
  for (double t0 : {0.0, 10.0, 20.0}) {
    const Drift d = drift10s(tr, t0);
    double wmax = 0;
    for (double t = t0; t < t0 + 10; t += 0.005) wmax = std::max(wmax, tr.angular_velocity(t).norm());
    INFO("V1_03 from " << 20 + t0 << " s, path " << path_length(tr, t0, t0 + 10) << " m, max |ω| " << wmax
                       << " rad/s: max drift pos " << d.pos << " m, vel " << d.vel << " m/s, rot " << d.rot << " rad");
    CHECK(d.pos < 0.01);
    CHECK(d.rot < 1e-4);
  }
}

TEST_CASE("The integration check detects an inconsistent IMU", "[sim][imu_simulator]") {
  // Negative controls for the two tests above: a 1 % gyro scale error or gravity off by 0.01 % (9.811
  // instead of 9.81) must each break the 1 cm bound.
  const SmoothTrajectory tr = trajectory_from_path({wp(0, 0, 0), wp(4, 0, 0), wp(4, 4, 0)}, PathProfile::handheld());
  const Drift scaled = drift10s(tr, 0.0, 9.81, 1.01);
  INFO("gyro scale 1.01: drift " << scaled.pos << " m");
  CHECK(scaled.pos > 0.01);
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  o.gravity = 9.811;
  const ImuSimulation s = ImuSimulator(o).simulate(tr, 0, 10'000'000'000LL);
  const GroundTruthState& g0 = s.truth.front();
  const State x = integrate_rk4({g0.q_wb, g0.p_wb, g0.v_wb}, s.samples, 0, 1000, 9.81);
  INFO("gravity 9.811 vs 9.81: drift " << (x.p - s.truth.back().p_wb).norm() << " m");
  CHECK((x.p - s.truth.back().p_wb).norm() > 0.01);
  // (A 5 ms timestamp offset moves this gentle path by only ~0.5 mm over 10 s, so timing is checked
  // exactly in "IMU timestamps and ground truth line up" instead.)
}

TEST_CASE("IMU at rest measures gravity in the body frame", "[sim][imu_simulator]") {
  const Eigen::Matrix3d R = so3::from_yaw_pitch_roll(0.7, 0.3, -0.2);
  const SmoothTrajectory tr = still(2.0, R);
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  const ImuSimulator sim(o);
  const ImuSimulation s = sim.simulate(tr);
  REQUIRE(s.samples.size() == 401);  // 0 .. 2 s inclusive at 200 Hz
  for (const ImuSample& m : s.samples) {
    // Specific force of a body at rest points up: R^T (0, 0, g).
    CHECK((m.acc - R.transpose() * Eigen::Vector3d(0, 0, 9.81)).norm() < 1e-12);
    CHECK(m.gyr.norm() < 1e-12);
  }
  const ImuSample level = sim.ideal_sample(still(1.0), 0.5);
  CHECK((level.acc - Eigen::Vector3d(0, 0, 9.81)).norm() < 1e-12);
}

TEST_CASE("IMU timestamps and ground truth line up", "[sim][imu_simulator]") {
  const SmoothTrajectory tr = trajectory_from_path({wp(0, 0, 0), wp(3, 1, 0)},
                                                 PathProfile::drone())
                                  .shifted_in_time(0.0123);
  ImuSimulatorOptions o;
  o.rate_hz = 400.0;
  const ImuSimulator sim(o);
  CHECK(sim.period_ns() == 2'500'000);
  const ImuSimulation s = sim.simulate(tr);
  REQUIRE(s.samples.size() == s.truth.size());
  CHECK(s.samples.front().t_ns == 12'500'000);  // first multiple of 2.5 ms at or after 12.3 ms
  CHECK(s.samples.back().t_ns <= std::llround(tr.t_max() * 1e9));
  CHECK(s.samples.back().t_ns + sim.period_ns() > std::llround(tr.t_max() * 1e9));
  for (size_t k = 0; k < s.samples.size(); ++k) {
    CHECK(s.truth[k].t_ns == s.samples[k].t_ns);
    if (k > 0) CHECK(s.samples[k].t_ns - s.samples[k - 1].t_ns == sim.period_ns());
    CHECK(s.truth[k].has_velocity);
    CHECK(s.truth[k].has_biases);
  }
  const size_t mid = s.truth.size() / 2;
  const double t = s.truth[mid].t_ns * 1e-9;
  CHECK((s.truth[mid].p_wb - tr.position(t)).norm() < 1e-12);
  CHECK((s.truth[mid].v_wb - tr.velocity(t)).norm() < 1e-12);
  CHECK(s.truth[mid].q_wb.angularDistance(tr.orientation(t)) < 1e-12);
  const GroundTruthState g = ground_truth_at(tr, s.truth[mid].t_ns);
  CHECK((g.p_wb - s.truth[mid].p_wb).norm() == 0.0);
  CHECK_FALSE(g.has_biases);

  CHECK_THROWS_AS(sim.simulate(tr, 0, 1'000'000'000), std::out_of_range);  // starts before the trajectory
  CHECK_THROWS_AS(sim.simulate(tr, 20'000'000, 10'000'000), std::invalid_argument);
}

TEST_CASE("IMU white noise has the configured density", "[sim][imu_simulator]") {
  const SmoothTrajectory tr = still(200.0, so3::from_yaw_pitch_roll(0.4, 0.1, 0.2));
  ImuSimulatorOptions o;
  o.noise.acc_random_walk = o.noise.gyr_random_walk = 0.0;  // isolate the white noise
  o.noise.acc_bias_initial = Eigen::Vector3d(0.1, -0.2, 0.05);
  o.noise.gyr_bias_initial = Eigen::Vector3d(-0.002, 0.02, 0.07);
  o.seed = 42;
  const ImuSimulator sim(o);
  const ImuSimulation s = sim.simulate(tr);
  const size_t n = s.samples.size();
  REQUIRE(n == 40001);
  const double dt = 0.005;
  const double sa = o.noise.acc_noise_density / std::sqrt(dt), sg = o.noise.gyr_noise_density / std::sqrt(dt);
  Eigen::Vector3d ma = Eigen::Vector3d::Zero(), mg = Eigen::Vector3d::Zero(), va = Eigen::Vector3d::Zero(),
                  vg = Eigen::Vector3d::Zero(), ca = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> na(n), ng(n);
  for (size_t k = 0; k < n; ++k) {
    const ImuSample ideal = sim.ideal_sample(tr, s.samples[k].t_ns * 1e-9);
    na[k] = s.samples[k].acc - ideal.acc - s.truth[k].bias_acc;
    ng[k] = s.samples[k].gyr - ideal.gyr - s.truth[k].bias_gyr;
    CHECK(s.truth[k].bias_acc == o.noise.acc_bias_initial);
    ma += na[k] / n;
    mg += ng[k] / n;
  }
  for (size_t k = 0; k < n; ++k) {
    va += (na[k] - ma).cwiseAbs2() / (n - 1);
    vg += (ng[k] - mg).cwiseAbs2() / (n - 1);
    if (k > 0) ca += (na[k] - ma).cwiseProduct(na[k - 1] - ma) / (n - 1);
  }
  INFO("acc σ " << va.cwiseSqrt().transpose() << " (expected " << sa << "), gyro σ " << vg.cwiseSqrt().transpose()
                << " (expected " << sg << ")");
  for (int i = 0; i < 3; ++i) {
    // Standard error of a sample std over n values is σ / sqrt(2n) = 0.35 %: 2 % is ~6 of them.
    CHECK(std::sqrt(va[i]) == Approx(sa).epsilon(0.02));
    CHECK(std::sqrt(vg[i]) == Approx(sg).epsilon(0.02));
    // Zero mean within 5 standard errors, and white: lag-1 correlation within 5 / sqrt(n).
    CHECK(std::abs(ma[i]) < 5 * sa / std::sqrt(double(n)));
    CHECK(std::abs(mg[i]) < 5 * sg / std::sqrt(double(n)));
    CHECK(std::abs(ca[i] / va[i]) < 5 / std::sqrt(double(n)));
  }
}

TEST_CASE("IMU bias random walk grows with the configured density", "[sim][imu_simulator]") {
  const SmoothTrajectory tr = still(1000.0);
  ImuSimulatorOptions o;
  o.noise.acc_noise_density = o.noise.gyr_noise_density = 0.0;  // isolate the walk
  o.noise.acc_bias_initial = Eigen::Vector3d(0.05, 0.0, -0.1);
  o.seed = 7;
  const ImuSimulator sim(o);
  const ImuSimulation s = sim.simulate(tr);
  const size_t n = s.samples.size();
  REQUIRE(n == 200001);
  // Without white noise the measurement is truth + bias exactly, and the ground truth carries that bias.
  double worst = 0.0;
  for (size_t k = 0; k < n; k += 97) {
    const ImuSample ideal = sim.ideal_sample(tr, s.samples[k].t_ns * 1e-9);
    worst = std::max(worst, (s.samples[k].acc - ideal.acc - s.truth[k].bias_acc).norm());
    worst = std::max(worst, (s.samples[k].gyr - ideal.gyr - s.truth[k].bias_gyr).norm());
  }
  CHECK(worst < 1e-12);
  CHECK(s.truth.front().bias_acc == o.noise.acc_bias_initial);
  // Var(b(t + L) - b(t)) = σ_w^2 L for a random walk; checked over non-overlapping windows of 1 s and
  // 10 s (3000 and 300 values: standard errors of the variance 2.6 % and 8 %; bounds at ~4.5 of them).
  auto growth = [&](double L, bool acc) {
    const size_t step = static_cast<size_t>(std::llround(L * 200));
    double v = 0;
    int m = 0;
    for (size_t k = 0; k + step < n; k += step) {
      const Eigen::Vector3d d = acc ? Eigen::Vector3d(s.truth[k + step].bias_acc - s.truth[k].bias_acc)
                                    : Eigen::Vector3d(s.truth[k + step].bias_gyr - s.truth[k].bias_gyr);
      v += d.squaredNorm();
      m += 3;
    }
    return v / m;
  };
  for (bool acc : {true, false}) {
    const double sw = acc ? o.noise.acc_random_walk : o.noise.gyr_random_walk;
    const double v1 = growth(1.0, acc), v10 = growth(10.0, acc);
    INFO((acc ? "acc" : "gyro") << " bias walk: std over 1 s " << std::sqrt(v1) << " (expected " << sw << "), over 10 s "
                                << std::sqrt(v10) << " (expected " << sw * std::sqrt(10.0) << ")");
    CHECK(v1 == Approx(sw * sw * 1.0).epsilon(0.12));
    CHECK(v10 == Approx(sw * sw * 10.0).epsilon(0.35));
  }
}

TEST_CASE("IMU simulation is deterministic for a seed", "[sim][imu_simulator]") {
  const SmoothTrajectory tr = still(5.0);
  ImuSimulatorOptions o;
  o.seed = 123;
  const ImuSimulation a = ImuSimulator(o).simulate(tr), b = ImuSimulator(o).simulate(tr);
  o.seed = 124;
  const ImuSimulation c = ImuSimulator(o).simulate(tr);
  REQUIRE(a.samples.size() == b.samples.size());
  bool same = true, differs = false;
  for (size_t k = 0; k < a.samples.size(); ++k) {
    same = same && a.samples[k].acc == b.samples[k].acc && a.samples[k].gyr == b.samples[k].gyr &&
           a.truth[k].bias_acc == b.truth[k].bias_acc;
    differs = differs || a.samples[k].acc != c.samples[k].acc;
  }
  CHECK(same);
  CHECK(differs);
}

TEST_CASE("ImuSimulator rejects bad options", "[sim][imu_simulator]") {
  ImuSimulatorOptions o;
  o.rate_hz = 0.0;
  CHECK_THROWS_AS(ImuSimulator(o), std::invalid_argument);
  o = {};
  o.noise.acc_noise_density = -1.0;
  CHECK_THROWS_AS(ImuSimulator(o), std::invalid_argument);
  o = {};
  o.noise.gyr_bias_initial.x() = NAN;
  CHECK_THROWS_AS(ImuSimulator(o), std::invalid_argument);
}
