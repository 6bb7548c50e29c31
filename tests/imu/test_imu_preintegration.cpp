// ImuPreintegration: deltas vs the simulator's ground truth (noise-free IMU), bias Jacobian vs numeric
// differentiation, first-order bias correction vs repropagation, covariance vs Monte Carlo, residual.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include "sim/motion/imu_simulator.hpp"
#include "stages/common/so3.hpp"
#include "tests/imu/wavy_trajectory.hpp"
#include "stages/imu/imu_preintegration.hpp"

using namespace dynavins;
using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

ImuSimulation simulate(const SmoothTrajectory& tr, double rate, int64_t t0, int64_t t1,
                       ImuNoiseModel noise = ImuNoiseModel::noise_free(), uint64_t seed = 1) {
  ImuSimulatorOptions o;
  o.rate_hz = rate;
  o.noise = noise;
  o.seed = seed;
  return ImuSimulator(o).simulate(tr, t0, t1);
}

imu::ImuPreintegration preintegrate(const std::vector<ImuSample>& s, const Eigen::Vector3d& ba = Eigen::Vector3d::Zero(),
                               const Eigen::Vector3d& bg = Eigen::Vector3d::Zero(), imu::ImuNoiseParams n = {}) {
  imu::ImuPreintegration p(s.front(), ba, bg, n);
  for (size_t k = 1; k < s.size(); ++k) p.integrate(s[k]);
  return p;
}

struct DeltaError {
  double p, v, r;
};

// Preintegrated deltas vs the true relative motion (VINS-Mono §VI-B with g_w = (0, 0, -9.81)).
DeltaError delta_error(const SmoothTrajectory& tr, const imu::ImuPreintegration& pre, int64_t t0, int64_t t1) {
  const KinematicState a = tr.evaluate(t0 * 1e-9), b = tr.evaluate(t1 * 1e-9);
  const double T = (t1 - t0) * 1e-9;
  const Eigen::Vector3d g(0, 0, -9.81);
  const Eigen::Vector3d alpha = a.R_wb.transpose() * (b.p_w - a.p_w - a.v_w * T - 0.5 * g * T * T);
  const Eigen::Vector3d beta = a.R_wb.transpose() * (b.v_w - a.v_w - g * T);
  const Eigen::Matrix3d gamma = a.R_wb.transpose() * b.R_wb;
  return {(pre.delta_p() - alpha).norm(), (pre.delta_v() - beta).norm(),
          so3::log(gamma.transpose() * pre.delta_q().toRotationMatrix()).norm()};
}

}  // namespace

TEST_CASE("preintegrated deltas match the true relative motion, second-order in the sample period",
          "[imu][preintegration]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const int64_t t0 = 3'000'000'000, t1 = 3'500'000'000;
  const imu::ImuPreintegration p200 = preintegrate(simulate(tr, 200.0, t0, t1).samples);
  const imu::ImuPreintegration p1000 = preintegrate(simulate(tr, 1000.0, t0, t1).samples);
  REQUIRE(p200.sum_dt() == Approx(0.5).epsilon(1e-12));
  const DeltaError e200 = delta_error(tr, p200, t0, t1), e1000 = delta_error(tr, p1000, t0, t1);
  INFO("200 Hz: p " << e200.p << " m, v " << e200.v << " m/s, r " << e200.r << " rad; 1 kHz: p " << e1000.p
                    << ", v " << e1000.v << ", r " << e1000.r);
  // The motion is large enough that a wrong sign or frame would show: |alpha| is metres.
  REQUIRE(p200.delta_p().norm() > 0.5);
  // 200 Hz errors far below what EuRoC-grade noise gives over 0.5 s (~1e-3 m, 1e-3 m/s, 1e-4 rad).
  CHECK(e200.p < 1e-4);
  CHECK(e200.v < 1e-4);
  CHECK(e200.r < 1e-5);
  // Midpoint rule: error ~ dt^2, so 5x the rate gives ~25x less; ask for at least 10x.
  CHECK(e1000.p < e200.p / 10.0);
  CHECK(e1000.v < e200.v / 10.0);
  CHECK(e1000.r < e200.r / 10.0);
}

TEST_CASE("integrate rejects samples that are not after the previous one", "[imu][preintegration]") {
  ImuSample s;
  s.t_ns = 100;
  imu::ImuPreintegration p(s, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), {});
  CHECK_THROWS_AS(p.integrate(s), std::invalid_argument);
}

TEST_CASE("bias Jacobian matches central differences of repropagation", "[imu][preintegration]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const std::vector<ImuSample> s = simulate(tr, 200.0, 2'000'000'000, 2'300'000'000).samples;
  const Eigen::Vector3d ba0(0.05, -0.03, 0.02), bg0(0.01, 0.005, -0.008);
  const imu::ImuPreintegration base = preintegrate(s, ba0, bg0);
  const imu::ImuPreintegration::Matrix15 J = base.jacobian();
  Eigen::Matrix<double, 9, 6> Jnum, Jana;
  const double h = 1e-4;
  for (int c = 0; c < 6; ++c) {
    Eigen::Matrix<double, 9, 1> d[2];
    for (int sgn = 0; sgn < 2; ++sgn) {
      Eigen::Vector3d ba = ba0, bg = bg0;
      (c < 3 ? ba(c) : bg(c - 3)) += (sgn == 0 ? h : -h);
      imu::ImuPreintegration p = base;
      p.repropagate(ba, bg);
      d[sgn].segment<3>(0) = p.delta_p();
      d[sgn].segment<3>(3) = so3::log(base.delta_q().toRotationMatrix().transpose() * p.delta_q().toRotationMatrix());
      d[sgn].segment<3>(6) = p.delta_v();
    }
    Jnum.col(c) = (d[0] - d[1]) / (2 * h);
  }
  Jana << J.block<3, 6>(0, 9), J.block<3, 6>(3, 9), J.block<3, 6>(6, 9);
  // F is the exact derivative of the discrete midpoint step, so only the finite difference differs:
  // truncation ~ h^2 |d3/db3| and rounding ~ 1e-16 |delta| / h, both < 1e-8 relative here; allow 1e-6.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 2; ++c) {
      const Eigen::Matrix3d a = Jana.block<3, 3>(3 * r, 3 * c), n = Jnum.block<3, 3>(3 * r, 3 * c);
      if (r == 1 && c == 0) {  // rotation does not depend on the accelerometer bias
        CHECK(a.norm() == 0.0);
        CHECK(n.norm() < 1e-8);
        continue;
      }
      const double rel = (a - n).norm() / n.norm();
      INFO("block (" << r << "," << c << ") |J| " << n.norm() << " relative error " << rel);
      CHECK(rel < 1e-6);
    }
}

TEST_CASE("first-order bias correction approximates repropagation to second order", "[imu][preintegration]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const std::vector<ImuSample> s = simulate(tr, 200.0, 1'000'000'000, 1'300'000'000).samples;
  const imu::ImuPreintegration base = preintegrate(s);
  auto errors = [&](double scale) {
    const Eigen::Vector3d ba = scale * Eigen::Vector3d(0.02, -0.015, 0.01);
    const Eigen::Vector3d bg = scale * Eigen::Vector3d(0.002, 0.003, -0.002);
    Eigen::Vector3d alpha, beta;
    Eigen::Quaterniond gamma;
    base.corrected_deltas(ba, bg, alpha, gamma, beta);
    imu::ImuPreintegration full = base;
    full.repropagate(ba, bg);
    const double change = (full.delta_p() - base.delta_p()).norm();
    const double err = (alpha - full.delta_p()).norm();
    const double err_v = (beta - full.delta_v()).norm();
    const double err_r = so3::log(gamma.toRotationMatrix().transpose() * full.delta_q().toRotationMatrix()).norm();
    return std::vector<double>{change, err, err_v, err_r};
  };
  const std::vector<double> e1 = errors(1.0), e2 = errors(2.0);
  INFO("alpha change " << e1[0] << " m; first-order error p " << e1[1] << " v " << e1[2] << " r " << e1[3]
                       << "; doubled: p " << e2[1] << " v " << e2[2] << " r " << e2[3]);
  CHECK(e1[1] < 0.01 * e1[0]);
  CHECK(base.bias_moved_far(Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d::Zero(), 0.1, 0.01));
  CHECK_FALSE(base.bias_moved_far(Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d::Zero(), 0.1, 0.01));
  // Remainder is quadratic in the bias change: doubling it gives ~4x (3..5 allows the cubic terms).
  for (int k = 1; k <= 3; ++k) {
    CHECK(e2[k] / e1[k] > 3.0);
    CHECK(e2[k] / e1[k] < 5.0);
  }
}

TEST_CASE("propagated covariance matches Monte Carlo on a noisy IMU", "[imu][preintegration][montecarlo]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const int64_t t0 = 4'000'000'000, t1 = 4'100'000'000;  // 0.1 s, 20 midpoint steps at 200 Hz
  const double rate = 200.0;
  // EuRoC-like densities, inflated so the noise dwarfs double rounding and the discretisation error.
  ImuNoiseModel nm;
  nm.acc_noise_density = 2.0e-2;
  nm.gyr_noise_density = 2.0e-3;
  nm.acc_random_walk = 3.0e-2;
  nm.gyr_random_walk = 2.0e-3;
  const imu::ImuNoiseParams np = imu::ImuNoiseParams::from_continuous_densities(
      nm.acc_noise_density, nm.gyr_noise_density, nm.acc_random_walk, nm.gyr_random_walk, 1.0 / rate);
  const imu::ImuPreintegration nominal = preintegrate(simulate(tr, rate, t0, t1).samples, Eigen::Vector3d::Zero(),
                                                 Eigen::Vector3d::Zero(), np);
  const imu::ImuPreintegration::Matrix15 P = nominal.covariance();
  const imu::ImuPreintegration::Matrix15 Pinv = P.inverse();

  const int runs = 500;
  std::vector<imu::ImuPreintegration::Vector15> err(runs);
  double nees = 0.0;
  for (int i = 0; i < runs; ++i) {
    const ImuSimulation sim = simulate(tr, rate, t0, t1, nm, 1000 + i);
    const imu::ImuPreintegration p = preintegrate(sim.samples, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), np);
    imu::ImuPreintegration::Vector15 e;
    e.segment<3>(0) = p.delta_p() - nominal.delta_p();
    e.segment<3>(3) = so3::log(nominal.delta_q().toRotationMatrix().transpose() * p.delta_q().toRotationMatrix());
    e.segment<3>(6) = p.delta_v() - nominal.delta_v();
    // The bias at the last sample: the walk accumulated over the interval's 20 steps.
    e.segment<3>(9) = sim.truth.back().bias_acc - sim.truth.front().bias_acc;
    e.segment<3>(12) = sim.truth.back().bias_gyr - sim.truth.front().bias_gyr;
    err[i] = e;
    nees += e.dot(Pinv * e) / runs;
  }
  imu::ImuPreintegration::Matrix15 S = imu::ImuPreintegration::Matrix15::Zero();
  for (const auto& e : err) S += e * e.transpose() / runs;  // mean is zero by construction

  // Sample variance over 500 runs has relative std sqrt(2/500) = 6.3%; the midpoint model also counts each
  // end sample at full weight, overstating white-noise variance by N/(N-1/2) = 2.6% at N = 20 steps.
  // Per diagonal entry: 4.5 sigma + 2.6% (15 entries, so a false alarm is < 1e-4).
  std::string report;
  for (int k = 0; k < 15; ++k) {
    const double ratio = S(k, k) / P(k, k);
    report += std::to_string(ratio) + " ";
    INFO("diag " << k << " MC " << S(k, k) << " propagated " << P(k, k) << " ratio " << ratio);
    CHECK(std::abs(ratio - 1.0) < 4.5 * 0.063 + 0.026);
  }
  // Mean NEES of a 15-dim Gaussian: 15 with std sqrt(2*15/500) = 0.245; 4.5 sigma + 2.6% of 15.
  INFO("MC/propagated diagonal ratios: " << report << " mean NEES " << nees << " (expect 15)");
  CHECK(std::abs(nees - 15.0) < 4.5 * 0.245 + 0.026 * 15.0);
  WARN("Monte Carlo diag ratios: " << report << "; mean NEES " << nees);
}

TEST_CASE("residual vanishes at the true states and sees a perturbation", "[imu][preintegration]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const int64_t t0 = 5'000'000'000, t1 = 5'200'000'000;
  const imu::ImuPreintegration pre = preintegrate(simulate(tr, 200.0, t0, t1).samples);
  const KinematicState a = tr.evaluate(t0 * 1e-9), b = tr.evaluate(t1 * 1e-9);
  const Eigen::Quaterniond qa(a.R_wb), qb(b.R_wb);
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  const auto r = pre.evaluate_residual(a.p_w, qa, a.v_w, z, z, b.p_w, qb, b.v_w, z, z);
  INFO("residual at truth " << r.transpose());
  CHECK(r.norm() < 1e-4);
  const auto rp = pre.evaluate_residual(a.p_w, qa, a.v_w, z, z, b.p_w + Eigen::Vector3d(0.01, 0, 0), qb, b.v_w, z, z);
  CHECK((rp - r).segment<3>(0).norm() == Approx(0.01).epsilon(1e-6));
  // Gravity enters: a residual with g = 0 is off by R_i^T g T.
  const auto r0 = pre.evaluate_residual(a.p_w, qa, a.v_w, z, z, b.p_w, qb, b.v_w, z, z, 0.0);
  CHECK((r0 - r).segment<3>(6).norm() == Approx(9.81 * 0.2).epsilon(1e-9));
}

TEST_CASE("predict reaches the end state and is what the residual measures against", "[imu][preintegration]") {
  const SmoothTrajectory tr = wavy_trajectory();
  const int64_t t0 = 5'000'000'000, t1 = 5'200'000'000;
  const imu::ImuPreintegration pre = preintegrate(simulate(tr, 200.0, t0, t1).samples);
  const KinematicState a = tr.evaluate(t0 * 1e-9), b = tr.evaluate(t1 * 1e-9);
  const Eigen::Quaterniond qa(a.R_wb), qb(b.R_wb);
  const Eigen::Vector3d z = Eigen::Vector3d::Zero(), ba(0.02, -0.01, 0.03), bg(0.001, 0.002, -0.001);
  Eigen::Vector3d p, v;
  Eigen::Quaterniond q;
  pre.predict(a.p_w, qa, a.v_w, z, z, 9.81, p, q, v);
  CHECK((p - b.p_w).norm() < 1e-4);
  CHECK((v - b.v_w).norm() < 1e-4);
  CHECK(q.angularDistance(qb) < 1e-4);
  // With other biases too, the predicted state has zero residual (both correct the deltas the same way).
  pre.predict(a.p_w, qa, a.v_w, ba, bg, 9.81, p, q, v);
  CHECK(pre.evaluate_residual(a.p_w, qa, a.v_w, ba, bg, p, q, v, ba, bg).norm() < 1e-12);
}
