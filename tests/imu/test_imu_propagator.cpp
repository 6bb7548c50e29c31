// ImuPropagator: IMU-rate propagation vs the simulator's ground truth, bias handling, replay after reset,
// rejection of out-of-order samples.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "sim/motion/imu_simulator.hpp"
#include "stages/common/so3.hpp"
#include "tests/imu/wavy_trajectory.hpp"
#include "stages/imu/imu_propagator.hpp"

using namespace dynavins;
using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

NavState truth_state(const SmoothTrajectory& tr, int64_t t_ns) {
  const GroundTruthState g = ground_truth_at(tr, t_ns);
  NavState s;
  s.t_ns = t_ns;
  s.p_wb = g.p_wb;
  s.q_wb = g.q_wb;
  s.v_wb = g.v_wb;
  return s;
}

struct Err {
  double p, v, r;
};
Err state_error(const SmoothTrajectory& tr, const NavState& s) {
  const NavState t = truth_state(tr, s.t_ns);
  return {(s.p_wb - t.p_wb).norm(), (s.v_wb - t.v_wb).norm(),
          so3::log(t.q_wb.toRotationMatrix().transpose() * s.q_wb.toRotationMatrix()).norm()};
}

}  // namespace

TEST_CASE("propagation follows the true trajectory over 1 s, with known biases removed", "[imu][propagator]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  o.noise.acc_bias_initial = Eigen::Vector3d(0.1, -0.2, 0.15);
  o.noise.gyr_bias_initial = Eigen::Vector3d(0.01, 0.02, -0.015);
  const std::vector<ImuSample> s = ImuSimulator(o).simulate(tr, 2'000'000'000, 3'000'000'000).samples;

  NavState x0 = truth_state(tr, 2'000'000'000);
  x0.bias_acc = o.noise.acc_bias_initial;
  x0.bias_gyr = o.noise.gyr_bias_initial;
  imu::ImuPropagator prop;
  CHECK_FALSE(prop.add_imu(s[0]).has_value());  // not initialised yet
  prop.reset(x0);
  NavState last;
  for (size_t k = 1; k < s.size(); ++k) {
    const auto r = prop.add_imu(s[k]);
    REQUIRE(r.has_value());
    CHECK(r->t_ns == s[k].t_ns);
    last = *r;
  }
  const Err e = state_error(tr, last);
  INFO("after 1 s: p " << e.p << " m, v " << e.v << " m/s, r " << e.r << " rad");
  // Midpoint at 200 Hz: O(dt^2) per unit time; 0.1 mm over 1 s is far below what a real IMU drifts.
  CHECK(e.p < 1e-4);
  CHECK(e.v < 1e-4);
  CHECK(e.r < 1e-5);

  // Ignoring the biases must be visibly worse (the test can fail if biases are not used).
  NavState xb = x0;
  xb.bias_acc.setZero();
  xb.bias_gyr.setZero();
  imu::ImuPropagator wrong;
  for (const ImuSample& x : s) wrong.add_imu(x);
  wrong.reset(xb);
  CHECK(state_error(tr, *wrong.latest()).p > 100 * e.p);
}

TEST_CASE("reset with an older state replays the buffered samples", "[imu][propagator]") {
  const SmoothTrajectory tr = wavy_trajectory(6.0);
  ImuSimulatorOptions o;
  o.noise = ImuNoiseModel::noise_free();
  const std::vector<ImuSample> s = ImuSimulator(o).simulate(tr, 1'000'000'000, 1'500'000'000).samples;
  // Estimator state at a frame time between samples.
  const int64_t tf = 1'202'500'000;
  imu::ImuPropagator a;
  for (const ImuSample& x : s) a.add_imu(x);
  a.reset(truth_state(tr, tf));
  const NavState ra = *a.latest();
  CHECK(ra.t_ns == s.back().t_ns);
  const Err e = state_error(tr, ra);
  INFO("replayed 0.3 s: p " << e.p << " v " << e.v << " r " << e.r);
  CHECK(e.p < 1e-4);
  CHECK(e.v < 1e-4);
  CHECK(e.r < 1e-5);
  // Out-of-order sample rejected and counted, state unchanged.
  CHECK_FALSE(a.add_imu(s[10]).has_value());
  CHECK(a.rejected_samples() == 1);
  CHECK((a.latest()->p_wb - ra.p_wb).norm() == 0.0);
}
