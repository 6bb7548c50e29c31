// Reprojection factors (two-frame one-cam, two-frame two-cam, one-frame two-cam): analytic Jacobians vs
// numeric differences, zero residual at the true state, the DynaVINS weight as a pure scale read at
// Evaluate time, and a small Ceres solve recovering a pose.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <memory>
#include <random>
#include <vector>

#include "stages/common/so3.hpp"
#include "stages/estimator/factors/reprojection_factors.hpp"
#include "tests/estimator/factor_jacobian_check.hpp"

using namespace dynavins;
using namespace dynavins::estimator;
using namespace dynavins::estimator::test;

namespace {

constexpr double kSqrtInfo = 460.0 / 1.5;  // focal length [px] / pixel sigma, VINS-Fusion's choice

struct Transform {
  Eigen::Vector3d p;
  Eigen::Matrix3d R;
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return R * x + p; }
  Eigen::Vector3d apply_inverse(const Eigen::Vector3d& x) const { return R.transpose() * (x - p); }
  Transform compose(const Transform& o) const { return {R * o.p + p, R * o.R}; }
  std::vector<double> block() const { return pose_block(p, R); }
};

Eigen::Vector3d random_vector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return Eigen::Vector3d(u(rng), u(rng), u(rng));
}

/// Two body poses, a stereo rig and one feature seen by cam0 and cam1 in both frames.
struct Scene {
  Transform T_wi, T_wj, T_bc0, T_bc1;
  double inv_depth;
  Eigen::Vector2d xy_i;    ///< anchor: cam0 at frame i
  Eigen::Vector3d P_w;     ///< the feature in the world
  Eigen::Vector2d cam0_j;  ///< true observation in cam0 at j
  Eigen::Vector2d cam1_j;  ///< true observation in cam1 at j
  Eigen::Vector2d cam1_i;  ///< true observation in cam1 at i

  /// The feature in camera `T_bc` of body pose `T_wb`.
  Eigen::Vector3d in_camera(const Transform& T_wb, const Transform& T_bc) const {
    return T_wb.compose(T_bc).apply_inverse(P_w);
  }
};

Eigen::Vector2d normalized(const Eigen::Vector3d& P) { return P.head<2>() / P.z(); }

Scene random_scene(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (;;) {
    Scene s;
    s.T_wi = {random_vector(rng, 5.0), so3::exp(random_vector(rng, 3.0))};
    // Camera looking along body x (z_cam = x_body), tilted a little, as on a typical rig.
    Eigen::Matrix3d cam_to_body;
    cam_to_body << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    s.T_bc0 = {random_vector(rng, 0.1), cam_to_body * so3::exp(random_vector(rng, 0.1))};
    const Transform T_c0c1{Eigen::Vector3d(0.11, 0.0, 0.0) + random_vector(rng, 0.01),
                           so3::exp(random_vector(rng, 0.02))};
    s.T_bc1 = s.T_bc0.compose(T_c0c1);
    s.T_wj = s.T_wi.compose(Transform{random_vector(rng, 0.4), so3::exp(random_vector(rng, 0.2))});
    s.xy_i = Eigen::Vector2d(0.4 * u(rng), 0.3 * u(rng));
    s.inv_depth = 1.0 / (4.0 + 3.0 * u(rng));
    s.P_w = s.T_wi.compose(s.T_bc0).apply(Eigen::Vector3d(s.xy_i.x(), s.xy_i.y(), 1.0) / s.inv_depth);
    const Eigen::Vector3d c0j = s.in_camera(s.T_wj, s.T_bc0), c1j = s.in_camera(s.T_wj, s.T_bc1),
                          c1i = s.in_camera(s.T_wi, s.T_bc1);
    if (c0j.z() < 1.0 || c1j.z() < 1.0 || c1i.z() < 1.0) continue;  // keep the point well in front
    s.cam0_j = normalized(c0j);
    s.cam1_j = normalized(c1j);
    s.cam1_i = normalized(c1i);
    return s;
  }
}

Eigen::Vector2d noise(std::mt19937& rng) { return random_vector(rng, 0.02).head<2>(); }

}  // namespace

TEST_CASE("reprojection factor Jacobians match numeric differences at random states",
          "[estimator][factors][reprojection]") {
  std::mt19937 rng(42);
  const double weight = 0.7;  // Jacobians must carry the weight too
  for (int trial = 0; trial < 8; ++trial) {
    const Scene s = random_scene(rng);
    const double* w = trial % 2 == 0 ? nullptr : &weight;
    INFO("trial " << trial);
    // Observations off the truth so that residuals (and the terms they multiply) are non-zero.
    const ProjectionTwoFrameOneCamFactor one_cam(s.xy_i, s.cam0_j + noise(rng), kSqrtInfo, w);
    require_jacobians_match_numeric(one_cam, {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(), {s.inv_depth}},
                                 {Block::Pose, Block::Pose, Block::Pose, Block::Euclidean});
    const ProjectionTwoFrameTwoCamFactor two_cam(s.xy_i, s.cam1_j + noise(rng), kSqrtInfo, w);
    require_jacobians_match_numeric(
        two_cam, {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(), s.T_bc1.block(), {s.inv_depth}},
        {Block::Pose, Block::Pose, Block::Pose, Block::Pose, Block::Euclidean});
    const ProjectionOneFrameTwoCamFactor stereo(s.xy_i, s.cam1_i + noise(rng), kSqrtInfo, w);
    require_jacobians_match_numeric(stereo, {s.T_bc0.block(), s.T_bc1.block(), {s.inv_depth}},
                                 {Block::Pose, Block::Pose, Block::Euclidean});
  }
}

TEST_CASE("reprojection residuals vanish at the true state and grow off it",
          "[estimator][factors][reprojection]") {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 10; ++trial) {
    const Scene s = random_scene(rng);
    const ProjectionTwoFrameOneCamFactor one_cam(s.xy_i, s.cam0_j, kSqrtInfo);
    const ProjectionTwoFrameTwoCamFactor two_cam(s.xy_i, s.cam1_j, kSqrtInfo);
    const ProjectionOneFrameTwoCamFactor stereo(s.xy_i, s.cam1_i, kSqrtInfo);
    CHECK(evaluate(one_cam, {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(), {s.inv_depth}}).residual.norm() <
          1e-9);
    CHECK(evaluate(two_cam, {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(), s.T_bc1.block(), {s.inv_depth}})
              .residual.norm() < 1e-9);
    CHECK(evaluate(stereo, {s.T_bc0.block(), s.T_bc1.block(), {s.inv_depth}}).residual.norm() < 1e-9);
    // A 20 % depth error moves the stereo and two-frame projections by many sigma; cam0 at i alone can't see it.
    const std::vector<double> wrong_depth = {1.2 * s.inv_depth};
    CHECK(evaluate(stereo, {s.T_bc0.block(), s.T_bc1.block(), wrong_depth}).residual.norm() > 0.5);
    // A 1 cm shift of pose_j moves the projection by ~ 0.01 / depth on the z = 1 plane (> 0.3 after scaling).
    Transform shifted = s.T_wj;
    shifted.p += 0.01 * (s.T_wj.R * s.T_bc0.R).col(0);  // along cam0's x axis: visible
    CHECK(evaluate(one_cam, {s.T_wi.block(), shifted.block(), s.T_bc0.block(), {s.inv_depth}}).residual.norm() >
          0.3);
  }
}

TEST_CASE("the DynaVINS weight scales residual and Jacobians and is read at Evaluate time",
          "[estimator][factors][reprojection]") {
  std::mt19937 rng(9);
  const Scene s = random_scene(rng);
  const Eigen::Vector2d obs0 = s.cam0_j + noise(rng), obs1 = s.cam1_j + noise(rng), obs_s = s.cam1_i + noise(rng);
  const std::vector<std::vector<double>> p_one = {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(), {s.inv_depth}};
  const std::vector<std::vector<double>> p_two = {s.T_wi.block(), s.T_wj.block(), s.T_bc0.block(),
                                                  s.T_bc1.block(), {s.inv_depth}};
  const std::vector<std::vector<double>> p_stereo = {s.T_bc0.block(), s.T_bc1.block(), {s.inv_depth}};
  double weight = 1.0;
  const ProjectionTwoFrameOneCamFactor one_u(s.xy_i, obs0, kSqrtInfo), one_w(s.xy_i, obs0, kSqrtInfo, &weight);
  const ProjectionTwoFrameTwoCamFactor two_u(s.xy_i, obs1, kSqrtInfo), two_w(s.xy_i, obs1, kSqrtInfo, &weight);
  const ProjectionOneFrameTwoCamFactor st_u(s.xy_i, obs_s, kSqrtInfo), st_w(s.xy_i, obs_s, kSqrtInfo, &weight);

  auto requireScaled = [&](const ceres::CostFunction& unweighted, const ceres::CostFunction& weighted,
                           const std::vector<std::vector<double>>& params, double w) {
    const Evaluation u = evaluate(unweighted, params), v = evaluate(weighted, params);
    REQUIRE(u.residual.norm() > 1.0);  // non-trivial residual
    CHECK((v.residual - w * u.residual).norm() <= 1e-14 * u.residual.norm());
    for (size_t b = 0; b < params.size(); ++b) {
      REQUIRE(u.jacobians[b].norm() > 0.0);
      CHECK((v.jacobians[b] - w * u.jacobians[b]).norm() <= 1e-14 * u.jacobians[b].norm());
    }
  };
  // Same factor objects, pointed-to value changed between evaluations (as the estimator does between solves).
  for (double w : {1.0, 0.3, 0.0}) {
    weight = w;
    INFO("weight " << w);
    requireScaled(one_u, one_w, p_one, w);
    requireScaled(two_u, two_w, p_two, w);
    requireScaled(st_u, st_w, p_stereo, w);
  }
}

TEST_CASE("a Ceres solve with two-frame reprojection factors recovers pose_j",
          "[estimator][factors][reprojection]") {
  std::mt19937 rng(2024);
  const Scene base = random_scene(rng);  // poses and rig; features drawn below
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Transform T_wc0i = base.T_wi.compose(base.T_bc0), T_wc0j = base.T_wj.compose(base.T_bc0);

  std::vector<double> pose_i = base.T_wi.block(), T_bc0 = base.T_bc0.block();
  const Transform start_j = base.T_wj.compose(Transform{Eigen::Vector3d(0.1, -0.08, 0.05),
                                                        so3::exp(Eigen::Vector3d(0.05, -0.08, 0.06))});
  std::vector<double> pose_j = start_j.block();
  std::vector<double> inv_depths;
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> observations;
  while (observations.size() < 15) {
    const Eigen::Vector2d xy_i(0.5 * u(rng), 0.4 * u(rng));
    const double inv_depth = 1.0 / (5.0 + 4.0 * u(rng));
    const Eigen::Vector3d P_ci = Eigen::Vector3d(xy_i.x(), xy_i.y(), 1.0) / inv_depth;
    const Eigen::Vector3d P_cj = T_wc0j.apply_inverse(T_wc0i.apply(P_ci));
    if (P_cj.z() < 1.0) continue;
    inv_depths.push_back(inv_depth);
    observations.emplace_back(xy_i, normalized(P_cj));
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  PoseManifold manifold;
  problem.AddParameterBlock(pose_i.data(), 7, &manifold);
  problem.AddParameterBlock(pose_j.data(), 7, &manifold);
  problem.AddParameterBlock(T_bc0.data(), 7, &manifold);
  problem.SetParameterBlockConstant(pose_i.data());
  problem.SetParameterBlockConstant(T_bc0.data());
  for (size_t k = 0; k < observations.size(); ++k) {
    problem.AddParameterBlock(&inv_depths[k], 1);
    problem.SetParameterBlockConstant(&inv_depths[k]);
    problem.AddResidualBlock(
        new ProjectionTwoFrameOneCamFactor(observations[k].first, observations[k].second, kSqrtInfo), nullptr,
        pose_i.data(), pose_j.data(), T_bc0.data(), &inv_depths[k]);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  INFO(summary.BriefReport());

  const Eigen::Vector3d p_j(pose_j[0], pose_j[1], pose_j[2]);
  const Eigen::Quaterniond q_j(Eigen::Map<const Eigen::Quaterniond>(pose_j.data() + 3));
  CHECK((start_j.p - base.T_wj.p).norm() > 0.05);  // it did start off
  CHECK((p_j - base.T_wj.p).norm() < 1e-6);
  CHECK(so3::log(base.T_wj.R.transpose() * q_j.toRotationMatrix()).norm() < 1e-6);
}
