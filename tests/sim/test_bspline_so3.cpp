// Cumulative cubic B-spline on SO(3): analytic body rates against numeric differentiation, continuity
// across knots, the fit Jacobians against numeric perturbation, and the SO(3) helpers it relies on.
#include <catch2/catch.hpp>

#include <random>

#include "sim/motion/bspline_so3.hpp"
#include "stages/common/so3.hpp"

using namespace dynavins::sim;
namespace so3 = dynavins::so3;

namespace {

// Random control rotations whose consecutive increments are up to `step` rad (a lively motion).
std::vector<Eigen::Matrix3d> random_control(int n, double step, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Matrix3d> c{so3::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 2.0)};
  for (int k = 1; k < n; ++k) c.push_back(c.back() * so3::exp(Eigen::Vector3d(u(rng), u(rng), u(rng)) * step / std::sqrt(3.0)));
  return c;
}

}  // namespace

TEST_CASE("so3 Exp/Log round trip and Jacobian identities", "[sim][so3]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double scale : {1e-9, 1e-4, 0.5, 2.0, 3.1}) {
    const Eigen::Vector3d phi = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * scale;
    const Eigen::Matrix3d R = so3::exp(phi);
    CHECK((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-14);
    CHECK((so3::log(R) - phi).norm() < 1e-12 * std::max(1.0, scale));
    CHECK((R - Eigen::Matrix3d(Eigen::AngleAxisd(scale, phi.normalized()))).norm() < 1e-14);
    CHECK((so3::right_jacobian(phi) * so3::right_jacobian_inverse(phi) - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    // Exp(φ + δ) ≈ Exp(φ) Exp(Jr(φ) δ): the error is second order in δ.
    const Eigen::Vector3d d(1e-6, -2e-6, 1.5e-6);
    CHECK(so3::log((R * so3::exp(so3::right_jacobian(phi) * d)).transpose() * so3::exp(phi + d)).norm() < 1e-11);
    // Log(Exp(δ) R) ≈ φ + Jl^-1(φ) δ (first order; skip the near-pi case where Log itself is ill-conditioned)
    if (scale < 3.0) CHECK((so3::log(so3::exp(d) * R) - phi - so3::left_jacobian_inverse(phi) * d).norm() < 1e-11);
  }
}

TEST_CASE("SO(3) spline body rates match numeric differentiation", "[sim][bspline_so3]") {
  const double dt = 0.1;
  const BSplineSO3 s(2.0, dt, random_control(14, 0.3, 11));
  const double h = 1e-5;
  double max_w_err = 0.0, max_a_err = 0.0, max_w = 0.0;
  for (double t = s.knots().t_min() + 2 * h; t < s.knots().t_max() - 2 * h; t += 0.0137) {
    const SplineSO3Value v = s.evaluate(t);
    CHECK((v.R.transpose() * v.R - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    // ω from the central difference of R: Log(R(t-h)^T R(t+h)) / 2h, error O(h^2).
    const Eigen::Vector3d w_num = so3::log(s.evaluate(t - h).R.transpose() * s.evaluate(t + h).R) / (2 * h);
    const Eigen::Vector3d a_num = (s.evaluate(t + h).omega - s.evaluate(t - h).omega) / (2 * h);
    max_w_err = std::max(max_w_err, (w_num - v.omega).norm());
    max_a_err = std::max(max_a_err, (a_num - v.alpha).norm());
    max_w = std::max(max_w, v.omega.norm());
  }
  INFO("max |ω| " << max_w << " rad/s, max ω error " << max_w_err << ", max α error " << max_a_err);
  CHECK(max_w > 1.0);  // the test motion is not trivially slow
  // Expected accuracy of the central differences: O(h^2 |d^3/dt^3|) ~ 1e-8; rounding ~ eps/h ~ 1e-11.
  CHECK(max_w_err < 1e-6);
  CHECK(max_a_err < 1e-5);
}

TEST_CASE("SO(3) spline is C2 across knots", "[sim][bspline_so3]") {
  const double dt = 0.05;
  const BSplineSO3 s(0.0, dt, random_control(10, 0.2, 3));
  for (int k = 1; k < s.knots().num_segments(); ++k) {
    const double tk = k * dt, e = 1e-9;
    const SplineSO3Value a = s.evaluate(tk - e), b = s.evaluate(tk + e);
    CHECK(so3::log(a.R.transpose() * b.R).norm() < 1e-7);
    CHECK((a.omega - b.omega).norm() < 1e-6);
    CHECK((a.alpha - b.alpha).norm() < 1e-4);  // α changes by at most |jerk| * 2e ~ 1e-6
  }
}

TEST_CASE("SO(3) spline reduces to a scalar B-spline about a fixed axis", "[sim][bspline_so3]") {
  // With all control rotations about one axis the increments commute, so the angle is the ordinary
  // cubic B-spline of the control angles and ω is its derivative.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -2).normalized();
  const std::vector<double> ang{0.1, 0.4, 0.2, -0.3, 0.5, 0.9};
  std::vector<Eigen::Matrix3d> c;
  for (double a : ang) c.push_back(so3::exp(a * axis));
  const double dt = 0.2;
  const BSplineSO3 s(0.0, dt, c);
  for (double t = 0.0; t <= s.knots().t_max(); t += 0.01) {
    const int i = std::min(static_cast<int>(t / dt), 2);
    const double u = t / dt - i;
    const double b[4] = {std::pow(1 - u, 3) / 6, (3 * u * u * u - 6 * u * u + 4) / 6,
                         (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6, u * u * u / 6};
    const double db[4] = {-0.5 * (1 - u) * (1 - u), 1.5 * u * u - 2 * u, -1.5 * u * u + u + 0.5, 0.5 * u * u};
    double th = 0, dth = 0;
    for (int j = 0; j < 4; ++j) {
      th += b[j] * ang[i + j];
      dth += db[j] * ang[i + j] / dt;
    }
    const SplineSO3Value v = s.evaluate(t);
    CHECK((so3::log(v.R) - th * axis).norm() < 1e-12);
    CHECK((v.omega - dth * axis).norm() < 1e-12);
  }
}

TEST_CASE("SO(3) spline Jacobians w.r.t. control points match numeric perturbation", "[sim][bspline_so3]") {
  const double dt = 0.1;
  const std::vector<Eigen::Matrix3d> c = random_control(8, 0.5, 5);
  const BSplineSO3 s(0.0, dt, c);
  const double eps = 1e-6;
  for (double t : {0.0, 0.031, 0.15, 0.2999, 0.37, 0.5}) {
    int first;
    std::array<Eigen::Matrix3d, 4> J;
    const Eigen::Matrix3d R = s.orientation_with_jacobians(t, first, J);
    CHECK(so3::log(R.transpose() * s.evaluate(t).R).norm() < 1e-14);
    for (int k = 0; k < 4; ++k)
      for (int ax = 0; ax < 3; ++ax) {
        std::vector<Eigen::Matrix3d> cp = c, cm = c;
        cp[first + k] = c[first + k] * so3::exp(Eigen::Vector3d::Unit(ax) * eps);
        cm[first + k] = c[first + k] * so3::exp(-Eigen::Vector3d::Unit(ax) * eps);
        const Eigen::Vector3d num = so3::log(BSplineSO3(0.0, dt, cm).evaluate(t).R.transpose() *
                                             BSplineSO3(0.0, dt, cp).evaluate(t).R) / (2 * eps);
        INFO("t=" << t << " control " << first + k << " axis " << ax);
        CHECK((num - J[k].col(ax)).norm() < 1e-8);
      }
  }
}

TEST_CASE("SO(3) spline rejects bad input", "[sim][bspline_so3]") {
  std::vector<Eigen::Matrix3d> c(3, Eigen::Matrix3d::Identity());
  CHECK_THROWS_AS(BSplineSO3(0.0, 0.1, c), std::invalid_argument);  // fewer than 4 control points
  c.push_back(Eigen::Matrix3d::Identity());
  CHECK_THROWS_AS(BSplineSO3(0.0, 0.0, c), std::invalid_argument);  // zero knot spacing
  c[2] = so3::exp(Eigen::Vector3d(0, 0, 3.1));
  CHECK_THROWS_AS(BSplineSO3(0.0, 0.1, c), std::invalid_argument);  // increment near pi
  c[2].setIdentity();
  const BSplineSO3 s(0.0, 0.1, c);
  CHECK_THROWS_AS(s.evaluate(-0.01), std::out_of_range);
  CHECK_THROWS_AS(s.evaluate(0.11), std::out_of_range);
  CHECK_NOTHROW(s.evaluate(0.1));
}
