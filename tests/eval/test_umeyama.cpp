// umeyama(): exact recovery of known SE(3) / Sim(3) transforms and its refusals.
#include "eval/umeyama.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <random>

using namespace dynavins::eval;

namespace {

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

Eigen::Matrix3Xd random_points(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  Eigen::Matrix3Xd p(3, count);
  for (int i = 0; i < count; ++i) p.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return p;
}

Eigen::Matrix3Xd apply(const Similarity3& T, const Eigen::Matrix3Xd& x) {
  Eigen::Matrix3Xd y(3, x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i) y.col(i) = T(x.col(i));
  return y;
}

}  // namespace

TEST_CASE("umeyama recovers random SE3 transforms exactly", "[eval][umeyama]") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Similarity3 truth;
    truth.R = random_rotation(rng);
    truth.t = 10.0 * random_points(rng, 1).col(0);
    const Eigen::Matrix3Xd src = random_points(rng, 3 + trial * 10);
    const Similarity3 got = umeyama(src, apply(truth, src), false);
    CHECK(got.s == 1.0);
    CHECK((got.R - truth.R).norm() < 1e-10);
    CHECK((got.t - truth.t).norm() < 1e-9);
    CHECK(got.R.determinant() == Approx(1.0).margin(1e-12));
  }
}

TEST_CASE("umeyama recovers random Sim3 transforms exactly", "[eval][umeyama]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> scale(0.1, 10.0);
  for (int trial = 0; trial < 20; ++trial) {
    Similarity3 truth;
    truth.R = random_rotation(rng);
    truth.t = 10.0 * random_points(rng, 1).col(0);
    truth.s = scale(rng);
    const Eigen::Matrix3Xd src = random_points(rng, 100);
    const Similarity3 got = umeyama(src, apply(truth, src), true);
    CHECK(got.s == Approx(truth.s).epsilon(1e-12));
    CHECK((got.R - truth.R).norm() < 1e-10);
    CHECK((got.t - truth.t).norm() < 1e-9);
    // Without scale the same data gives s = 1 and a worse fit, never a silently scaled one.
    CHECK(umeyama(src, apply(truth, src), false).s == 1.0);
  }
}

TEST_CASE("umeyama returns a proper rotation for mirrored data", "[eval][umeyama]") {
  std::mt19937 rng(3);
  const Eigen::Matrix3Xd src = random_points(rng, 30);
  Eigen::Matrix3Xd mirrored = src;
  mirrored.row(2) *= -1.0;  // no rotation maps src onto this; the best one still has det +1
  const Similarity3 got = umeyama(src, mirrored, true);
  CHECK(got.R.determinant() == Approx(1.0).margin(1e-12));
  CHECK(got.s > 0.0);
}

TEST_CASE("umeyama on planar data (a ground robot) is still exact", "[eval][umeyama]") {
  std::mt19937 rng(5);
  Eigen::Matrix3Xd src = random_points(rng, 40);
  src.row(2).setZero();
  Similarity3 truth;
  truth.R = random_rotation(rng);
  truth.t = {1, 2, 3};
  truth.s = 0.5;
  const Similarity3 got = umeyama(src, apply(truth, src), true);
  CHECK((got.R - truth.R).norm() < 1e-10);
  CHECK(got.s == Approx(0.5).epsilon(1e-12));
}

TEST_CASE("umeyama rejects mismatched, too few and collinear points", "[eval][umeyama]") {
  std::mt19937 rng(1);
  const Eigen::Matrix3Xd a = random_points(rng, 10);
  const Eigen::Matrix3Xd nine = a.leftCols(9), two = a.leftCols(2);
  CHECK_THROWS_AS(umeyama(a, nine, false), std::invalid_argument);
  CHECK_THROWS_AS(umeyama(two, two, false), std::invalid_argument);
  Eigen::Matrix3Xd line(3, 10);
  for (int i = 0; i < 10; ++i) line.col(i) = Eigen::Vector3d(1, 2, 3) * static_cast<double>(i);
  CHECK_THROWS_WITH(umeyama(line, line, true), Catch::Contains("degenerate"));
  const Eigen::Matrix3Xd same = Eigen::Matrix3Xd::Ones(3, 5);
  CHECK_THROWS_AS(umeyama(same, same, false), std::runtime_error);
}
