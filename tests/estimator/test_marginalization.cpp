// MarginalizationInfo / MarginalizationFactor: the prior left by marginalising states reproduces the full
// problem's solution and covariance (linear-Gaussian), keeps a nonlinear pose graph at its optimum, has
// exact Jacobians, ignores unrelated dropped blocks, weights by the robust loss, and keeps its block order.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <array>
#include <functional>
#include <memory>
#include <random>
#include <set>
#include <vector>

#include <Eigen/Dense>
#include <ceres/ceres.h>

#include "stages/common/so3.hpp"
#include "stages/estimator/marginalization/marginalization_factor.hpp"
#include "stages/estimator/marginalization/marginalization_info.hpp"
#include "stages/estimator/pose_manifold.hpp"
#include "tests/estimator/factor_jacobian_check.hpp"

using namespace dynavins;
using namespace dynavins::estimator;

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Eigen::MatrixXd random_matrix(int rows, int cols, std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = u(rng);
  return m;
}

/// r = Σ_k A_k x_k - c over Euclidean blocks.
class LinearFactor final : public ceres::CostFunction {
 public:
  LinearFactor(std::vector<Eigen::MatrixXd> a, Eigen::VectorXd c) : a_(std::move(a)), c_(std::move(c)) {
    for (const auto& ak : a_) mutable_parameter_block_sizes()->push_back(static_cast<int>(ak.cols()));
    set_num_residuals(static_cast<int>(c_.size()));
  }
  bool Evaluate(double const* const* x, double* r, double** jac) const override {
    Eigen::Map<Eigen::VectorXd> res(r, c_.size());
    res = -c_;
    for (size_t k = 0; k < a_.size(); ++k) {
      res += a_[k] * Eigen::Map<const Eigen::VectorXd>(x[k], a_[k].cols());
      if (jac && jac[k]) Eigen::Map<RowMajor>(jac[k], a_[k].rows(), a_[k].cols()) = a_[k];
    }
    return true;
  }
  const std::vector<Eigen::MatrixXd>& a() const { return a_; }
  const Eigen::VectorXd& c() const { return c_; }

 private:
  std::vector<Eigen::MatrixXd> a_;
  Eigen::VectorXd c_;
};

using ResidualFn = std::function<Eigen::VectorXd(const std::vector<const double*>&)>;

/// A cost from a residual function with numeric tangent Jacobians (factor_jacobian_check.hpp's central
/// differences): size-7 blocks perturbed through PoseManifold::Plus and written in the first 6 columns
/// (column 7 zero), others additively — the estimator's convention.
class NumericTangentCost final : public ceres::CostFunction {
 public:
  NumericTangentCost(ResidualFn f, std::vector<int> sizes, int rows) : f_(std::move(f)) {
    for (int s : sizes) mutable_parameter_block_sizes()->push_back(s);
    set_num_residuals(rows);
  }
  bool Evaluate(double const* const* x, double* r, double** jac) const override {
    const std::vector<int32_t>& sizes = parameter_block_sizes();
    std::vector<const double*> ptrs(x, x + sizes.size());
    Eigen::Map<Eigen::VectorXd>(r, num_residuals()) = f_(ptrs);
    if (!jac) return true;
    test::BlockValues values;
    for (size_t i = 0; i < sizes.size(); ++i) values.emplace_back(x[i], x[i] + sizes[i]);
    const test::ResidualFunction residual = [this](const test::BlockValues& v) {
      std::vector<const double*> p;
      for (const auto& block : v) p.push_back(block.data());
      return f_(p);
    };
    for (size_t i = 0; i < sizes.size(); ++i) {
      if (!jac[i]) continue;
      const test::Block kind = sizes[i] == 7 ? test::Block::Pose : test::Block::Euclidean;
      Eigen::Map<RowMajor> ji(jac[i], num_residuals(), sizes[i]);
      ji.setZero();
      const RowMajor numeric = test::numeric_tangent_jacobian(residual, values, i, kind);
      ji.leftCols(numeric.cols()) = numeric;
    }
    return true;
  }

 private:
  ResidualFn f_;
};

using Pose = std::array<double, 7>;

Pose make_pose(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return {p.x(), p.y(), p.z(), q.x(), q.y(), q.z(), q.w()};
}
Eigen::Vector3d pos_of(const double* x) { return Eigen::Map<const Eigen::Vector3d>(x); }
Eigen::Matrix3d rot_of(const double* x) {
  return Eigen::Map<const Eigen::Quaterniond>(x + 3).normalized().toRotationMatrix();
}

/// Pose prior: W [p - p_m; Log(R_m^T R)].
std::shared_ptr<ceres::CostFunction> pose_prior(const Pose& measured, double weight) {
  return std::make_shared<NumericTangentCost>(
      [measured, weight](const std::vector<const double*>& x) {
        Eigen::VectorXd r(6);
        r.head<3>() = pos_of(x[0]) - pos_of(measured.data());
        r.tail<3>() = so3::log(rot_of(measured.data()).transpose() * rot_of(x[0]));
        return Eigen::VectorXd(weight * r);
      },
      std::vector<int>{7}, 6);
}

/// Relative pose: W [R_i^T (p_j - p_i) - dp_m; Log(dR_m^T R_i^T R_j)].
std::shared_ptr<ceres::CostFunction> relative_pose(const Eigen::Vector3d& dp, const Eigen::Matrix3d& dR, double weight) {
  return std::make_shared<NumericTangentCost>(
      [dp, dR, weight](const std::vector<const double*>& x) {
        const Eigen::Matrix3d Ri = rot_of(x[0]);
        Eigen::VectorXd r(6);
        r.head<3>() = Ri.transpose() * (pos_of(x[1]) - pos_of(x[0])) - dp;
        r.tail<3>() = so3::log(dR.transpose() * Ri.transpose() * rot_of(x[1]));
        return Eigen::VectorXd(weight * r);
      },
      std::vector<int>{7, 7}, 6);
}

/// A factor of a test problem: cost (+ loss) over blocks given by index.
struct TestFactor {
  std::shared_ptr<ceres::CostFunction> cost;
  std::vector<int> blocks;
  std::shared_ptr<ceres::LossFunction> loss;
};

/// Marginalises `dropped` (block indices): every factor touching one goes into the info.
std::shared_ptr<MarginalizationInfo> marginalize_blocks(const std::vector<TestFactor>& factors,
                                                       const std::vector<double*>& blocks,
                                                       const std::set<int>& dropped) {
  auto info = std::make_shared<MarginalizationInfo>();
  for (const TestFactor& f : factors) {
    ResidualBlockInfo res;
    res.cost = f.cost;
    res.loss = f.loss;
    for (size_t k = 0; k < f.blocks.size(); ++k) {
      res.blocks.push_back(blocks[f.blocks[k]]);
      if (dropped.count(f.blocks[k])) res.drop.push_back(static_cast<int>(k));
    }
    if (!res.drop.empty()) info->add(std::move(res));
  }
  info->linearize();
  info->marginalize();
  return info;
}

/// Adds the factors touching none of `dropped` to `problem`.
void add_remaining_factors(ceres::Problem& problem, const std::vector<TestFactor>& factors,
                         const std::vector<double*>& blocks, const std::set<int>& dropped) {
  for (const TestFactor& f : factors) {
    bool touches = false;
    std::vector<double*> ptrs;
    for (int b : f.blocks) {
      touches |= dropped.count(b) > 0;
      ptrs.push_back(blocks[b]);
    }
    // The problem does not own the test's shared costs.
    if (!touches) problem.AddResidualBlock(f.cost.get(), f.loss.get(), ptrs);
  }
}

ceres::Problem::Options non_owning_options() {
  ceres::Problem::Options o;
  o.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return o;
}

ceres::Solver::Options tight_solver_options() {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.max_num_iterations = 100;
  o.function_tolerance = 1e-20;
  o.gradient_tolerance = 1e-20;
  o.parameter_tolerance = 1e-20;
  o.initial_trust_region_radius = 1e8;
  return o;
}

/// Dense Jacobian of `problem` over `blocks` (tangent columns) at the current values.
Eigen::MatrixXd dense_jacobian(ceres::Problem& problem, const std::vector<double*>& blocks) {
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  problem.Evaluate(eo, nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row)
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) j(row, crs.cols[k]) = crs.values[k];
  return j;
}

/// Gauss-Newton H = J^T J and b = J^T r of all `factors` (loss-corrected, as Ceres evaluates them), the
/// columns in the order of `order`: the dense reference the marginalization is checked against.
struct DenseSystem {
  Eigen::MatrixXd H;
  Eigen::VectorXd b;
};
DenseSystem dense_system(const std::vector<TestFactor>& factors, const std::vector<double*>& blocks,
                        const std::vector<double*>& order) {
  ceres::Problem problem(non_owning_options());
  add_remaining_factors(problem, factors, blocks, {});
  const Eigen::MatrixXd J = dense_jacobian(problem, order);
  std::vector<double> gradient;
  ceres::Problem::EvaluateOptions eo;
  eo.parameter_blocks = order;
  problem.Evaluate(eo, nullptr, nullptr, &gradient, nullptr);
  return {J.transpose() * J, Eigen::Map<const Eigen::VectorXd>(gradient.data(), static_cast<Eigen::Index>(gradient.size()))};
}

/// Linear chain x0..x4 (size 3): prior on x0 and x4, odometry x_i -> x_{i+1}, loops x0-x2 and x1-x3.
std::vector<TestFactor> linear_chain(std::mt19937& rng) {
  auto sqrtInfo = [&rng] { return Eigen::MatrixXd(2.0 * Eigen::MatrixXd::Identity(3, 3) + random_matrix(3, 3, rng, 0.5)); };
  auto link = [&](int i, int j) {
    const Eigen::MatrixXd a = sqrtInfo();
    return TestFactor{std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{-a, a},
                                                     Eigen::VectorXd(random_matrix(3, 1, rng))),
                      {i, j}, nullptr};
  };
  std::vector<TestFactor> f;
  f.push_back({std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{sqrtInfo()}, Eigen::VectorXd(random_matrix(3, 1, rng))), {0}, nullptr});
  for (int i = 0; i < 4; ++i) f.push_back(link(i, i + 1));
  f.push_back(link(0, 2));
  f.push_back(link(1, 3));
  f.push_back({std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{sqrtInfo()}, Eigen::VectorXd(random_matrix(3, 1, rng))), {4}, nullptr});
  return f;
}

}  // namespace

TEST_CASE("Marginalising a linear-Gaussian chain keeps the exact solution and marginal covariance",
          "[estimator][marginalization]") {
  std::mt19937 rng(7);
  const std::vector<TestFactor> factors = linear_chain(rng);
  constexpr int kBlocks = 5;

  // Full problem densely: r(x) = J x - c stacked, x* = (J^T J)^-1 J^T c, covariance (J^T J)^-1.
  int rows = 0;
  for (const auto& f : factors) rows += f.cost->num_residuals();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows, 3 * kBlocks);
  Eigen::VectorXd c(rows);
  int row = 0;
  for (const auto& f : factors) {
    const auto& lin = static_cast<const LinearFactor&>(*f.cost);
    for (size_t k = 0; k < f.blocks.size(); ++k) J.block(row, 3 * f.blocks[k], 3, 3) = lin.a()[k];
    c.segment(row, 3) = lin.c();
    row += 3;
  }
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd x_star = H.ldlt().solve(J.transpose() * c);
  const Eigen::MatrixXd covariance = H.inverse();

  for (const std::set<int>& dropped : {std::set<int>{0}, std::set<int>{0, 1}}) {
    const int first_kept = static_cast<int>(dropped.size());
    std::vector<std::array<double, 3>> x(kBlocks);
    std::vector<double*> blocks;
    for (auto& xi : x) {
      const Eigen::Vector3d v = random_matrix(3, 1, rng, 2.0);  // arbitrary linearisation point
      xi = {v.x(), v.y(), v.z()};
      blocks.push_back(xi.data());
    }
    const auto info = marginalize_blocks(factors, blocks, dropped);
    REQUIRE(info->kept_tangent_size() == 6);  // x1,x2 (or x2,x3) share a factor with the dropped blocks

    ceres::Problem problem(non_owning_options());
    MarginalizationFactor prior(info);
    problem.AddResidualBlock(&prior, nullptr, info->kept_blocks());
    add_remaining_factors(problem, factors, blocks, dropped);
    for (int i = first_kept; i < kBlocks; ++i) x[i] = {0.0, 0.0, 0.0};  // start away from the optimum
    ceres::Solver::Summary summary;
    ceres::Solve(tight_solver_options(), &problem, &summary);

    const std::vector<double*> kept(blocks.begin() + first_kept, blocks.end());
    for (int i = first_kept; i < kBlocks; ++i) {
      INFO("dropped " << dropped.size() << " block(s), block " << i);
      CHECK((Eigen::Map<const Eigen::Vector3d>(x[i].data()) - x_star.segment<3>(3 * i)).cwiseAbs().maxCoeff() < 1e-8);
    }
    const Eigen::MatrixXd Jr = dense_jacobian(problem, kept);
    const Eigen::MatrixXd reduced_cov = (Jr.transpose() * Jr).inverse();
    const int n = 3 * (kBlocks - first_kept);
    const Eigen::MatrixXd full_cov = covariance.bottomRightCorner(n, n);
    INFO("dropped " << dropped.size() << " block(s)");
    CHECK((reduced_cov - full_cov).cwiseAbs().maxCoeff() < 1e-8);
  }
}

TEST_CASE("Marginalising the first pose at the optimum keeps the pose graph's optimum",
          "[estimator][marginalization]") {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.05);
  auto noisy3 = [&] { return Eigen::Vector3d(noise(rng), noise(rng), noise(rng)); };
  constexpr int kPoses = 4;
  std::vector<Eigen::Vector3d> p_true;
  std::vector<Eigen::Matrix3d> R_true;
  for (int i = 0; i < kPoses; ++i) {
    p_true.emplace_back(1.0 * i, 0.3 * std::sin(i), 0.1 * i * i);
    R_true.push_back(so3::from_yaw_pitch_roll(0.4 * i, 0.1 * i, -0.05 * i));
  }
  // Noisy measurements, so the optimum fits none of them exactly.
  std::vector<TestFactor> factors;
  factors.push_back({pose_prior(make_pose(p_true[0] + noisy3(), R_true[0] * so3::exp(noisy3())), 10.0), {0}, nullptr});
  for (auto [i, j] : std::vector<std::pair<int, int>>{{0, 1}, {1, 2}, {2, 3}, {0, 2}, {1, 3}}) {
    const Eigen::Vector3d dp = R_true[i].transpose() * (p_true[j] - p_true[i]) + noisy3();
    const Eigen::Matrix3d dR = R_true[i].transpose() * R_true[j] * so3::exp(noisy3());
    factors.push_back({relative_pose(dp, dR, 3.0), {i, j}, nullptr});
  }

  std::vector<Pose> x(kPoses);
  std::vector<double*> blocks;
  for (int i = 0; i < kPoses; ++i) {
    x[i] = make_pose(p_true[i] + 3 * noisy3(), R_true[i] * so3::exp(3 * noisy3()));
    blocks.push_back(x[i].data());
  }
  PoseManifold manifold;
  {
    ceres::Problem full(non_owning_options());
    add_remaining_factors(full, factors, blocks, {});
    for (double* b : blocks) full.SetManifold(b, &manifold);
    ceres::Solver::Summary summary;
    ceres::Solve(tight_solver_options(), &full, &summary);
    REQUIRE(summary.IsSolutionUsable());
  }
  const std::vector<Pose> optimum = x;

  const auto info = marginalize_blocks(factors, blocks, {0});
  REQUIRE(info->kept_blocks() == std::vector<double*>{blocks[1], blocks[2]});

  ceres::Problem reduced(non_owning_options());
  MarginalizationFactor prior(info);
  reduced.AddResidualBlock(&prior, nullptr, info->kept_blocks());
  add_remaining_factors(reduced, factors, blocks, {0});
  for (int i = 1; i < kPoses; ++i) {
    x[i] = make_pose(pos_of(x[i].data()) + Eigen::Vector3d(0.2, -0.1, 0.15), rot_of(x[i].data()) * so3::exp(Eigen::Vector3d(0.1, -0.08, 0.12)));
    reduced.SetManifold(x[i].data(), &manifold);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(tight_solver_options(), &reduced, &summary);
  for (int i = 1; i < kPoses; ++i) {
    INFO("pose " << i);
    CHECK((pos_of(x[i].data()) - pos_of(optimum[i].data())).norm() < 1e-6);
    CHECK(so3::log(rot_of(optimum[i].data()).transpose() * rot_of(x[i].data())).norm() < 1e-6);
  }
}

TEST_CASE("MarginalizationFactor Jacobians match numeric differentiation through PoseManifold::Plus",
          "[estimator][marginalization]") {
  std::mt19937 rng(3);
  // Pose 0 tied to pose 1, a 9-dim speed-bias-like block and pose 2; marginalise pose 0.
  Pose t0 = make_pose({0, 0, 0}, Eigen::Matrix3d::Identity());
  Pose t1 = make_pose({1, 0.2, -0.1}, so3::exp({0.1, 0.3, -0.2}));
  Pose t2 = make_pose({2, 0.1, 0.3}, so3::exp({-0.2, 0.6, 0.1}));
  std::array<double, 9> sb{};
  for (double& v : sb) v = std::uniform_real_distribution<double>(-1, 1)(rng);
  auto sb_factor = std::make_shared<NumericTangentCost>(
      [](const std::vector<const double*>& x) {
        Eigen::VectorXd r(9);
        r.head<3>() = rot_of(x[0]).transpose() * Eigen::Map<const Eigen::Vector3d>(x[1]) - Eigen::Vector3d(1, 0, 0);
        r.tail<6>() = 2.0 * Eigen::Map<const Eigen::Matrix<double, 6, 1>>(x[1] + 3);
        return r;
      },
      std::vector<int>{7, 9}, 9);
  const std::vector<TestFactor> factors{
      {pose_prior(make_pose({0.1, 0, 0}, so3::exp({0, 0, 0.1})), 5.0), {0}, nullptr},
      {relative_pose({1, 0, 0}, so3::exp({0.1, 0.2, -0.3}), 2.0), {0, 1}, nullptr},
      {sb_factor, {0, 2}, nullptr},
      {relative_pose({2, 0, 0}, so3::exp({-0.1, 0.5, 0.2}), 2.0), {0, 3}, nullptr},
  };
  const std::vector<double*> blocks{t0.data(), t1.data(), sb.data(), t2.data()};
  const auto info = marginalize_blocks(factors, blocks, {0});
  MarginalizationFactor prior(info);
  REQUIRE(prior.parameter_block_sizes() == std::vector<int32_t>{7, 9, 7});
  const int rows = prior.num_residuals();
  REQUIRE(rows == info->kept_tangent_size());  // t1 (6) + sb (9) + t2 (6), full rank

  // At the linearisation point the residual is r0.
  {
    Eigen::VectorXd r(rows);
    const double* params[] = {t1.data(), sb.data(), t2.data()};
    prior.Evaluate(params, r.data(), nullptr);
    CHECK((r - info->linearized_residual()).cwiseAbs().maxCoeff() < 1e-12);
  }

  // Far from it (rotations moved ~0.5 rad), analytic vs numeric.
  const PoseManifold manifold;
  Pose t1m, t2m;
  const Eigen::Matrix<double, 6, 1> d1 = (Eigen::Matrix<double, 6, 1>() << 0.3, -0.2, 0.1, 0.4, -0.3, 0.2).finished();
  const Eigen::Matrix<double, 6, 1> d2 = (Eigen::Matrix<double, 6, 1>() << -0.1, 0.5, 0.2, -0.2, 0.35, -0.4).finished();
  manifold.Plus(t1.data(), d1.data(), t1m.data());
  manifold.Plus(t2.data(), d2.data(), t2m.data());
  std::array<double, 9> sbm = sb;
  for (double& v : sbm) v += 0.3;
  const test::BlockValues params{{t1m.begin(), t1m.end()}, {sbm.begin(), sbm.end()}, {t2m.begin(), t2m.end()}};
  test::require_jacobians_match_numeric(prior, params, {test::Block::Pose, test::Block::Euclidean, test::Block::Pose});
  const RowMajor analytic0 = test::evaluate(prior, params).jacobians[0];
  // The identity approximation of d Log / dθ would be off by far more than the tolerance here.
  CHECK((analytic0.middleCols<3>(3) - info->linearized_jacobian().middleCols<3>(3)).cwiseAbs().maxCoeff() > 1e-3);
}

TEST_CASE("Dropping a block that shares no factor with the kept ones leaves the prior unchanged",
          "[estimator][marginalization]") {
  std::mt19937 rng(5);
  const std::vector<TestFactor> chain = linear_chain(rng);
  std::vector<std::array<double, 3>> x(6, std::array<double, 3>{0.3, -0.2, 0.5});
  std::vector<double*> blocks;
  for (auto& xi : x) blocks.push_back(xi.data());
  std::vector<TestFactor> with_isolated = chain;
  with_isolated.push_back({std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Identity(3, 3)},
                                                          Eigen::VectorXd::Ones(3)),
                           {5}, nullptr});
  const auto plain = marginalize_blocks(chain, blocks, {0});
  const auto isolated = marginalize_blocks(with_isolated, blocks, {0, 5});
  REQUIRE(isolated->kept_blocks() == plain->kept_blocks());
  const Eigen::MatrixXd& J1 = plain->linearized_jacobian();
  const Eigen::MatrixXd& J2 = isolated->linearized_jacobian();
  CHECK((J1.transpose() * J1 - J2.transpose() * J2).cwiseAbs().maxCoeff() < 1e-10);
  CHECK((J1.transpose() * plain->linearized_residual() - J2.transpose() * isolated->linearized_residual())
            .cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("A Huber loss on a marginalised factor weights its information by rho'",
          "[estimator][marginalization]") {
  // x (dropped) and y (kept); r_A = x - y, r_B = x - m under Huber(a). With rho' = rho'(r_B^2):
  //   H = [1+rho' -1; -1 1], b = [r_A + rho' r_B; -r_A]  ->  H* = rho'/(1+rho'), b* = rho'(r_B - r_A)/(1+rho').
  const double m = 0.0;
  double x = 2.0, y = 1.5;
  const double r_a = x - y, r_b = x - m;
  for (const double a : {0.5, 5.0}) {
    const double rho1 = std::abs(r_b) > a ? a / std::abs(r_b) : 1.0;  // Huber: rho'(s) = a / sqrt(s) past a^2
    const std::vector<TestFactor> factors{
        {std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Ones(1, 1), -Eigen::MatrixXd::Ones(1, 1)},
                                        Eigen::VectorXd::Zero(1)),
         {0, 1}, nullptr},
        {std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Ones(1, 1)}, Eigen::VectorXd::Constant(1, m)),
         {0}, std::make_shared<ceres::HuberLoss>(a)},
    };
    const auto info = marginalize_blocks(factors, {&x, &y}, {0});
    const Eigen::MatrixXd& J = info->linearized_jacobian();
    INFO("Huber a = " << a << ", rho' = " << rho1);
    REQUIRE(J.rows() == 1);
    CHECK((J.transpose() * J)(0, 0) == Approx(rho1 / (1.0 + rho1)).epsilon(1e-12));
    CHECK((J.transpose() * info->linearized_residual())(0) == Approx(rho1 * (r_b - r_a) / (1.0 + rho1)).epsilon(1e-12));
  }
}

/// rho(s) = s + s^2 / 4: rho'' > 0, so Ceres applies the second-order Corrector branch.
class StiffeningLoss final : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    rho[0] = s + 0.25 * s * s;
    rho[1] = 1.0 + 0.5 * s;
    rho[2] = 0.5;
  }
};

TEST_CASE("Robust losses enter the prior exactly as Ceres' own Gauss-Newton system has them",
          "[estimator][marginalization]") {
  // x (size 2, dropped), y (size 2, kept); Huber on one factor, a rho'' > 0 loss on another. Ceres'
  // Problem::Evaluate returns the loss-corrected Jacobian and gradient; their Schur complement onto y
  // must equal the prior's J^T J and J^T r0.
  std::mt19937 rng(19);
  std::array<double, 2> x{1.5, -0.7}, y{0.4, 0.9};
  auto linear = [&rng](int blocks) {
    std::vector<Eigen::MatrixXd> a;
    for (int k = 0; k < blocks; ++k) a.push_back(random_matrix(2, 2, rng) + (k == 0 ? 2.0 : -1.0) * Eigen::MatrixXd::Identity(2, 2));
    return std::make_shared<LinearFactor>(a, Eigen::VectorXd(random_matrix(2, 1, rng)));
  };
  const std::vector<TestFactor> factors{
      {linear(2), {0, 1}, std::make_shared<StiffeningLoss>()},
      {linear(1), {0}, std::make_shared<ceres::HuberLoss>(0.3)},
      {linear(2), {1, 0}, nullptr},
  };
  const std::vector<double*> blocks{x.data(), y.data()};

  const auto [H, b] = dense_system(factors, blocks, blocks);
  const Eigen::Matrix2d h_star = H.bottomRightCorner<2, 2>() - H.bottomLeftCorner<2, 2>() * H.topLeftCorner<2, 2>().inverse() * H.topRightCorner<2, 2>();
  const Eigen::Vector2d b_star = b.tail<2>() - H.bottomLeftCorner<2, 2>() * H.topLeftCorner<2, 2>().inverse() * b.head<2>();

  const auto info = marginalize_blocks(factors, blocks, {0});
  const Eigen::MatrixXd& Jm = info->linearized_jacobian();
  CHECK((Jm.transpose() * Jm - h_star).cwiseAbs().maxCoeff() < 1e-10);
  CHECK((Jm.transpose() * info->linearized_residual() - b_star).cwiseAbs().maxCoeff() < 1e-10);
  // Both losses are really active here (else this test would not exercise the corrections).
  double rho[3];
  Eigen::VectorXd r(2);
  const double* px[] = {x.data(), y.data()};
  factors[0].cost->Evaluate(px, r.data(), nullptr);
  StiffeningLoss().Evaluate(r.squaredNorm(), rho);
  CHECK(rho[1] > 1.2);
  factors[1].cost->Evaluate(px, r.data(), nullptr);
  CHECK(r.norm() > 0.3);
}

TEST_CASE("Scalar dropped blocks (inverse depths) are eliminated to the same Schur complement as a dense H",
          "[estimator][marginalization]") {
  // Dropped: p (size 3, like a pose) and scalars d0..d5 (like inverse depths); kept: k0 (3), k1 (2).
  // d0..d3 each sit in factors with p/k0/k1 only (eliminated one by one), d4 and d5 share a factor (so
  // both go through the dense pseudo-inverse); one variant gives d3 no information at all (H_dd = 0).
  for (const bool uninformative : {false, true}) {
    std::mt19937 rng(uninformative ? 31 : 29);
    std::array<double, 3> p{0.1, 0.2, 0.3}, k0{1, -1, 0.5};
    std::array<double, 2> k1{0.3, 0.7};
    std::vector<std::array<double, 1>> d(6);
    for (size_t i = 0; i < d.size(); ++i) d[i] = {0.2 + 0.1 * static_cast<double>(i)};
    std::vector<double*> blocks{p.data(), k0.data(), k1.data()};
    for (auto& di : d) blocks.push_back(di.data());
    const std::vector<int> sizes{3, 3, 2, 1, 1, 1, 1, 1, 1};
    auto factor = [&](std::vector<int> idx, int rows, std::shared_ptr<ceres::LossFunction> loss = nullptr) {
      std::vector<Eigen::MatrixXd> a;
      for (int i : idx) {
        a.push_back(random_matrix(rows, sizes[i], rng));
        if (uninformative && i == 6) a.back().setZero();
      }
      return TestFactor{std::make_shared<LinearFactor>(a, Eigen::VectorXd(random_matrix(rows, 1, rng))), idx, loss};
    };
    std::vector<TestFactor> factors{
        factor({0}, 3),  // p alone
        factor({0, 1}, 3),
        factor({0, 1, 3}, 2),
        factor({0, 2, 3}, 2, std::make_shared<ceres::HuberLoss>(0.2)),
        factor({0, 1, 4}, 2),
        factor({1, 2, 4}, 2),
        factor({0, 2, 5}, 2),
        factor({5}, 1),
        factor({0, 1, 6}, 2),
        factor({0, 1, 7, 8}, 2),
        factor({0, 2, 7}, 2),
        factor({1, 8}, 1),
    };
    const std::set<int> dropped{0, 3, 4, 5, 6, 7, 8};
    const auto info = marginalize_blocks(factors, blocks, dropped);
    REQUIRE(info->kept_blocks() == std::vector<double*>{k0.data(), k1.data()});

    // Reference: Ceres' own Jacobian and gradient, Schur complement with a pseudo-inverse of H_mm.
    std::vector<double*> order;  // dropped first, then kept
    for (int i : {0, 3, 4, 5, 6, 7, 8, 1, 2}) order.push_back(blocks[i]);
    const auto [H, b] = dense_system(factors, blocks, order);
    const int m = 9, n = 5;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H.topLeftCorner(m, m));
    const Eigen::VectorXd inv = (eig.eigenvalues().array() > 1e-8).select(eig.eigenvalues().array().inverse(), 0.0);
    const Eigen::MatrixXd hmm_inv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
    const Eigen::MatrixXd h_star = H.bottomRightCorner(n, n) - H.bottomLeftCorner(n, m) * hmm_inv * H.topRightCorner(m, n);
    const Eigen::VectorXd b_star = b.tail(n) - H.bottomLeftCorner(n, m) * hmm_inv * b.head(m);

    const Eigen::MatrixXd& Jm = info->linearized_jacobian();
    INFO("uninformative d3: " << uninformative);
    CHECK((Jm.transpose() * Jm - h_star).cwiseAbs().maxCoeff() < 1e-9 * h_star.cwiseAbs().maxCoeff());
    CHECK((Jm.transpose() * info->linearized_residual() - b_star).cwiseAbs().maxCoeff() <
          1e-9 * (1.0 + b_star.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("kept_blocks follows the linearized column order and applies the address shift",
          "[estimator][marginalization]") {
  // Kept blocks of sizes 3, 1, 2 with priors of distinct weights, plus a dropped block d linked to a.
  std::array<double, 3> c{1, 2, 3};
  std::array<double, 1> a{0.5};
  std::array<double, 2> b{-1, 1};
  std::array<double, 2> d{0.2, 0.4};
  auto prior = [](int size, double w) {
    return std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{w * Eigen::MatrixXd::Identity(size, size)},
                                          Eigen::VectorXd::Zero(size));
  };
  const std::vector<TestFactor> factors{
      {prior(3, 3.0), {0}, nullptr},
      {prior(1, 1.0), {1}, nullptr},
      {std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Ones(1, 2), Eigen::MatrixXd::Ones(1, 1)},
                                      Eigen::VectorXd::Zero(1)),
       {3, 1}, nullptr},
      {prior(2, 1.0), {3}, nullptr},
      {prior(2, 2.0), {2}, nullptr},
  };
  // Every prior is added with a dropped block so that all blocks enter the info.
  MarginalizationInfo info;
  const std::vector<double*> blocks{c.data(), a.data(), b.data(), d.data()};
  for (const TestFactor& f : factors) {
    ResidualBlockInfo res{f.cost, f.loss, {}, {}};
    for (int k : f.blocks) res.blocks.push_back(blocks[k]);
    if (f.blocks.front() == 3) res.drop = {0};
    info.add(res);
  }
  info.linearize();
  info.marginalize();

  REQUIRE(info.kept_blocks() == std::vector<double*>{c.data(), a.data(), b.data()});
  REQUIRE(info.kept_sizes() == std::vector<int>{3, 1, 2});
  REQUIRE(info.kept_tangent_offsets() == std::vector<int>{0, 3, 4});
  // The diagonal of J^T J identifies each block: c -> 9, b -> 4, a -> prior 1 + link 1 minus the Schur
  // term of d (H_dd = I + 1 1^T, H_da = 1: 1^T H_dd^-1 1 = 2/3).
  const Eigen::MatrixXd H = info.linearized_jacobian().transpose() * info.linearized_jacobian();
  CHECK((H.diagonal() - (Eigen::VectorXd(6) << 9, 9, 9, 1.0 + 1.0 - 2.0 / 3.0, 4, 4).finished()).cwiseAbs().maxCoeff() < 1e-12);

  std::array<double, 3> c_new{};
  std::array<double, 2> b_new{};
  const std::unordered_map<const double*, double*> shift{{c.data(), c_new.data()}, {b.data(), b_new.data()}};
  CHECK(info.kept_blocks(shift) == std::vector<double*>{c_new.data(), a.data(), b_new.data()});
}

TEST_CASE("Marginalising every block throws", "[estimator][marginalization]") {
  std::array<double, 2> x{1, 2};
  MarginalizationInfo info;
  info.add({std::make_shared<LinearFactor>(std::vector<Eigen::MatrixXd>{Eigen::MatrixXd::Identity(2, 2)}, Eigen::VectorXd::Zero(2)),
            nullptr, {x.data()}, {0}});
  info.linearize();
  CHECK_THROWS_AS(info.marginalize(), std::runtime_error);
  CHECK_THROWS_AS(info.add({nullptr, nullptr, {x.data()}, {}}), std::logic_error);
}
