// ImuFactor: analytic Jacobians vs numeric differences at random states, zero residual at the true states
// of a closed-form motion, ||r||² = e^T P^-1 e, and reading the preintegration at Evaluate time.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <random>
#include <vector>

#include <Eigen/Cholesky>

#include "stages/common/so3.hpp"
#include "stages/estimator/factors/imu_factor.hpp"
#include "tests/estimator/factor_jacobian_check.hpp"

using namespace dynavins;
using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

namespace {

constexpr double kGravity = 9.81;

/// Constant world acceleration a_w and constant body rate ω: R(t) = R0 Exp(ω t), p(t) = p0 + v0 t + ½ a_w t².
struct ClosedFormMotion {
  Eigen::Vector3d p0, v0, a_w, omega;
  Eigen::Matrix3d R0;
  Eigen::Vector3d ba, bg;  ///< true IMU biases
  Eigen::Matrix3d R(double t) const { return R0 * so3::exp(omega * t); }
  Eigen::Vector3d p(double t) const { return p0 + v0 * t + 0.5 * a_w * t * t; }
  Eigen::Vector3d v(double t) const { return v0 + a_w * t; }
  ImuSample sample(int64_t t_ns) const {
    const double t = t_ns * 1e-9;
    ImuSample s;
    s.t_ns = t_ns;
    s.acc = R(t).transpose() * (a_w - Eigen::Vector3d(0, 0, -kGravity)) + ba;  // specific force
    s.gyr = omega + bg;
    return s;
  }
  std::vector<double> pose(double t) const { return pose_block(p(t), R(t)); }
  std::vector<double> speed_bias(double t) const {
    const Eigen::Vector3d vt = v(t);
    return {vt.x(), vt.y(), vt.z(), ba.x(), ba.y(), ba.z(), bg.x(), bg.y(), bg.z()};
  }
};

Eigen::Vector3d random_vector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Eigen::Vector3d(u(rng), u(rng), u(rng));
}

ClosedFormMotion random_motion(std::mt19937& rng) {
  ClosedFormMotion m;
  m.p0 = random_vector(rng, 5.0);
  m.v0 = random_vector(rng, 2.0);
  m.a_w = random_vector(rng, 2.0);
  m.omega = random_vector(rng, 1.0);
  m.R0 = so3::exp(random_vector(rng, 3.0));
  m.ba = random_vector(rng, 0.2);
  m.bg = random_vector(rng, 0.05);
  return m;
}

/// Preintegration of the motion's noise-free samples over [0, duration] at 1 kHz, linearised at (ba, bg).
imu::ImuPreintegration preintegrate(const ClosedFormMotion& m, double duration, const Eigen::Vector3d& ba,
                               const Eigen::Vector3d& bg) {
  const int64_t step_ns = 1'000'000;
  const int64_t end_ns = static_cast<int64_t>(duration * 1e9);
  imu::ImuPreintegration pre(m.sample(0), ba, bg, imu::ImuNoiseParams{});
  for (int64_t t = step_ns; t <= end_ns; t += step_ns) pre.integrate(m.sample(t));
  return pre;
}

std::vector<double> plus_vector(std::vector<double> x, const Eigen::VectorXd& d) {
  for (int k = 0; k < d.size(); ++k) x[k] += d[k];
  return x;
}

}  // namespace

TEST_CASE("ImuFactor Jacobians match numeric differences at random states", "[estimator][factors][imu]") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    const ClosedFormMotion m = random_motion(rng);
    // Linearised away from the state's biases so the bias-correction terms are exercised.
    const Eigen::Vector3d lin_ba = m.ba + random_vector(rng, 0.05), lin_bg = m.bg + random_vector(rng, 0.02);
    const imu::ImuPreintegration pre = preintegrate(m, 0.5, lin_ba, lin_bg);
    const ImuFactor factor(&pre, kGravity);
    // States away from the motion: residuals of all 15 rows non-zero.
    const PoseManifold manifold;
    std::vector<double> pose_i = m.pose(0.0), pose_j = m.pose(0.5);
    Eigen::Matrix<double, 6, 1> d;
    d << random_vector(rng, 0.3), random_vector(rng, 0.3);
    manifold.Plus(m.pose(0.0).data(), d.data(), pose_i.data());
    d << random_vector(rng, 0.3), random_vector(rng, 0.3);
    manifold.Plus(m.pose(0.5).data(), d.data(), pose_j.data());
    Eigen::Matrix<double, 9, 1> s;
    s << random_vector(rng, 0.5), random_vector(rng, 0.05), random_vector(rng, 0.02);
    const std::vector<double> sb_i = plus_vector(m.speed_bias(0.0), s);
    s << random_vector(rng, 0.5), random_vector(rng, 0.05), random_vector(rng, 0.02);
    const std::vector<double> sb_j = plus_vector(m.speed_bias(0.5), s);
    INFO("trial " << trial);
    // Compared unwhitened (S^-1 J): whitened rows differ in scale by ~1e3 and would hide errors in the small ones.
    const Eigen::MatrixXd unwhiten = ImuFactor::sqrt_information(pre.covariance()).inverse();
    require_jacobians_match_numeric(factor, {pose_i, sb_i, pose_j, sb_j},
                                 {Block::Pose, Block::Euclidean, Block::Pose, Block::Euclidean}, unwhiten);
  }
}

TEST_CASE("ImuFactor residual vanishes at the true states of a closed-form motion", "[estimator][factors][imu]") {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 4; ++trial) {
    const ClosedFormMotion m = random_motion(rng);
    const imu::ImuPreintegration pre = preintegrate(m, 0.5, m.ba, m.bg);
    const ImuFactor factor(&pre, kGravity);
    const Evaluation at_truth = evaluate(factor, {m.pose(0.0), m.speed_bias(0.0), m.pose(0.5), m.speed_bias(0.5)});
    // Midpoint integration is exact here (R(t) f(t) is constant in the world), so only round-off remains.
    CHECK(at_truth.residual.norm() < 1e-6);
    // A 1 mm error in p_j is visible (position std over 0.5 s with these noise params is ~ 1e-2 m / 10).
    std::vector<double> pose_j = m.pose(0.5);
    pose_j[0] += 1e-3;
    const Evaluation off = evaluate(factor, {m.pose(0.0), m.speed_bias(0.0), pose_j, m.speed_bias(0.5)});
    CHECK(off.residual.norm() > 1e-2);
  }
}

TEST_CASE("ImuFactor whitening gives the Mahalanobis norm of the preintegration residual",
          "[estimator][factors][imu]") {
  std::mt19937 rng(3);
  const ClosedFormMotion m = random_motion(rng);
  const imu::ImuPreintegration pre = preintegrate(m, 0.3, m.ba, m.bg);
  const Eigen::Matrix<double, 15, 15> S = ImuFactor::sqrt_information(pre.covariance());
  CHECK((S.triangularView<Eigen::StrictlyLower>().toDenseMatrix()).cwiseAbs().maxCoeff() == 0.0);
  const ImuFactor factor(&pre, kGravity);
  std::vector<double> pose_j = m.pose(0.3), sb_j = m.speed_bias(0.3);
  pose_j[1] += 0.02;
  sb_j[2] -= 0.05;
  sb_j[7] += 1e-3;
  const Evaluation ev = evaluate(factor, {m.pose(0.0), m.speed_bias(0.0), pose_j, sb_j});
  const Eigen::Map<const Eigen::Vector3d> Pj(pose_j.data()), Vj(sb_j.data()), Baj(sb_j.data() + 3),
      Bgj(sb_j.data() + 6);
  const Eigen::Quaterniond Qj(Eigen::Map<const Eigen::Quaterniond>(pose_j.data() + 3));
  const imu::ImuPreintegration::Vector15 e =
      pre.evaluate_residual(m.p(0), Eigen::Quaterniond(m.R(0)), m.v(0), m.ba, m.bg, Pj, Qj, Vj, Baj, Bgj, kGravity);
  const double mahalanobis = e.dot(pre.covariance().ldlt().solve(e));
  CHECK(ev.residual.squaredNorm() == Approx(mahalanobis).epsilon(1e-8));
  CHECK(mahalanobis > 1.0);  // the perturbation is many sigma: the comparison is not between two zeros
}

TEST_CASE("ImuFactor reads the preintegration at Evaluate time", "[estimator][factors][imu]") {
  std::mt19937 rng(5);
  const ClosedFormMotion m = random_motion(rng);
  imu::ImuPreintegration pre = preintegrate(m, 0.5, m.ba, m.bg + Eigen::Vector3d(0.1, -0.1, 0.05));
  const ImuFactor factor(&pre, kGravity);
  const std::vector<std::vector<double>> truth = {m.pose(0.0), m.speed_bias(0.0), m.pose(0.5), m.speed_bias(0.5)};
  const double before = evaluate(factor, truth).residual.norm();
  // Bias error in the gyro: first-order correction leaves a second-order rotation error until relinearised.
  pre.repropagate(m.ba, m.bg);
  const double after = evaluate(factor, truth).residual.norm();
  CHECK(after < 1e-6);
  CHECK(before > 1e3 * after);
}
