// SmoothTrajectory: exact derivatives against numeric differentiation, C2 continuity at the knots, and
// the bookkeeping (range, pose, time shift).
#include <catch2/catch.hpp>

#include <random>

#include "sim/motion/smooth_trajectory.hpp"
#include "stages/common/so3.hpp"

using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

SmoothTrajectory random_trajectory(double t0, double dt, int n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Matrix3d> r{Eigen::Matrix3d::Identity()};
  for (int k = 0; k < n; ++k) p.emplace_back(3 * u(rng), 3 * u(rng), u(rng));
  for (int k = 1; k < n; ++k) r.push_back(r.back() * so3::exp(0.25 * Eigen::Vector3d(u(rng), u(rng), u(rng))));
  return SmoothTrajectory(BSplineR3(t0, dt, p), BSplineSO3(t0, dt, r));
}

}  // namespace

TEST_CASE("SmoothTrajectory derivatives match numeric differentiation", "[sim][smooth_trajectory]") {
  const SmoothTrajectory tr = random_trajectory(5.0, 0.2, 12, 21);
  const double h = 1e-5;
  double ev = 0, ea = 0, ej = 0, ew = 0, eal = 0, amax = 0;
  for (double t = tr.t_min() + 2 * h; t < tr.t_max() - 2 * h; t += 0.0173) {
    const KinematicState s = tr.evaluate(t), m = tr.evaluate(t - h), p = tr.evaluate(t + h);
    ev = std::max(ev, ((p.p_w - m.p_w) / (2 * h) - s.v_w).norm());
    ea = std::max(ea, ((p.v_w - m.v_w) / (2 * h) - s.a_w).norm());
    // Jerk is piecewise constant: the central difference is exact away from knots, skip straddling ones.
    const double u = (t - tr.t_min()) / tr.knot_spacing();
    if (std::abs(u - std::round(u)) * tr.knot_spacing() > 2 * h) ej = std::max(ej, ((p.a_w - m.a_w) / (2 * h) - s.j_w).norm());
    ew = std::max(ew, (so3::log(m.R_wb.transpose() * p.R_wb) / (2 * h) - s.omega_b).norm());
    eal = std::max(eal, ((p.omega_b - m.omega_b) / (2 * h) - s.alpha_b).norm());
    amax = std::max(amax, s.a_w.norm());
    // The convenience accessors agree with evaluate().
    CHECK((tr.position(t) - s.p_w).norm() == 0.0);
    CHECK((tr.velocity(t) - s.v_w).norm() == 0.0);
    CHECK((tr.acceleration(t) - s.a_w).norm() == 0.0);
    CHECK((tr.rotation(t) - s.R_wb).norm() == 0.0);
    CHECK((tr.angular_velocity(t) - s.omega_b).norm() == 0.0);
  }
  INFO("max |a| " << amax << "; errors v " << ev << " a " << ea << " j " << ej << " ω " << ew << " α " << eal);
  CHECK(amax > 10.0);
  // Central differences with h = 1e-5: truncation ~ h^2 * (next derivative) and rounding ~ 1e-16 |x| / h.
  CHECK(ev < 1e-7);
  CHECK(ea < 1e-6);
  CHECK(ej < 1e-4);
  CHECK(ew < 1e-7);
  CHECK(eal < 1e-5);
}

TEST_CASE("SmoothTrajectory is C2 at the knots", "[sim][smooth_trajectory]") {
  const SmoothTrajectory tr = random_trajectory(0.0, 0.1, 9, 4);
  double jump_j = 0.0;
  for (int k = 1; k < 6; ++k) {
    // Either side of the knot by 1e-12 s: a continuous quantity moves by at most 2e-12 times its rate of
    // change (here up to ~1e3 per second of acceleration, ~1e4 of jerk), i.e. far below these bounds.
    const double tk = k * 0.1, e = 1e-12;
    const KinematicState a = tr.evaluate(tk - e), b = tr.evaluate(tk + e);
    CHECK((a.p_w - b.p_w).norm() < 1e-10);
    CHECK((a.v_w - b.v_w).norm() < 1e-8);
    CHECK((a.a_w - b.a_w).norm() < 1e-6);
    CHECK((a.omega_b - b.omega_b).norm() < 1e-8);
    CHECK((a.alpha_b - b.alpha_b).norm() < 1e-6);
    jump_j = std::max(jump_j, (a.j_w - b.j_w).norm());
  }
  CHECK(jump_j > 1.0);  // a cubic spline is only C2: the jerk does jump, so the checks above can fail
}

TEST_CASE("SmoothTrajectory range, pose and time shift", "[sim][smooth_trajectory]") {
  const SmoothTrajectory tr = random_trajectory(1.0, 0.25, 7, 9);
  CHECK(tr.t_min() == 1.0);
  CHECK(tr.t_max() == Approx(2.0));
  CHECK(tr.duration() == Approx(1.0));
  CHECK(tr.knot_spacing() == 0.25);
  CHECK_THROWS_AS(tr.evaluate(0.99), std::out_of_range);
  CHECK_THROWS_AS(tr.evaluate(2.01), std::out_of_range);
  CHECK_NOTHROW(tr.evaluate(2.0 + 1e-10));

  const Eigen::Isometry3d T = tr.pose(1.3);
  CHECK((T.translation() - tr.position(1.3)).norm() == 0.0);
  CHECK((T.linear() - tr.rotation(1.3)).norm() == 0.0);
  CHECK(tr.orientation(1.3).angularDistance(Eigen::Quaterniond(tr.rotation(1.3))) < 1e-12);

  const SmoothTrajectory sh = tr.shifted_in_time(-1.0);
  CHECK(sh.t_min() == 0.0);
  for (double t : {0.0, 0.33, 0.99}) {
    const KinematicState a = sh.evaluate(t), b = tr.evaluate(t + 1.0);
    CHECK((a.p_w - b.p_w).norm() < 1e-12);
    CHECK((a.a_w - b.a_w).norm() < 1e-9);
    CHECK((a.omega_b - b.omega_b).norm() < 1e-10);
  }

  // Splines on different knot grids cannot form one trajectory.
  CHECK_THROWS_AS(SmoothTrajectory(tr.position_spline(), sh.orientation_spline()), std::invalid_argument);
}
