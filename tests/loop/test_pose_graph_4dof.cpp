// PoseGraph4Dof (paper IV-C eq. 15, VINS-Fusion's 4-DoF graph) on the synthetic two-lap square: without
// loops the solve keeps the odometry; exact loops remove most of the drift; roll and pitch stay at the
// odometry's; the yaw manifold handles the ±pi wrap; Huber and switchable edges behave as documented.
#include "tests/estimator/catch_with_ceres.hpp"  // first: Catch's CHECK, not glog's

#include <algorithm>
#include <unordered_map>

#include "stages/loop/graph/pose_graph_4dof.hpp"
#include "tests/loop/loop_graph_scenario.hpp"

using namespace dynavins;
using namespace dynavins::loop;
using dynavins::loop::test::kDeg;
using dynavins::loop::test::LoopScenario;

namespace {
std::vector<LoopEdge> edges_of(const LoopScenario& s) {
  std::unordered_map<int64_t, int> node;
  for (std::size_t k = 0; k < s.t_ns.size(); ++k) node[s.t_ns[k]] = static_cast<int>(k);
  std::vector<LoopEdge> e;
  for (const VerifiedLoop& l : s.loops)
    e.push_back(LoopEdge{node[l.match_t_ns], node[l.query_t_ns], RigidPose{l.p_mq, l.q_mq}, 1.0});
  return e;
}
}  // namespace

TEST_CASE("PoseGraph4Dof: no loops keeps the odometry", "[loop][posegraph]") {
  const LoopScenario s;
  PoseGraph4Dof g(s.odom);
  const PoseGraphSolveReport r = g.solve({}, LoopEdgeLoss::Plain);
  CHECK(r.usable);
  CHECK(r.final_cost < 1e-12);
  for (std::size_t k = 0; k < s.odom.size(); ++k) {
    CHECK((g.pose(k).p - s.odom[k].p).norm() < 1e-6);
    CHECK(g.pose(k).q.angularDistance(s.odom[k].q) < 1e-6);
  }
}

TEST_CASE("PoseGraph4Dof: exact loops remove the drift, roll and pitch stay", "[loop][posegraph]") {
  LoopScenario s;
  for (int j = 0; j < 8; ++j) s.add_true_loops_in_group(j);
  PoseGraph4Dof g(s.odom);
  const double before = s.rmse(g.poses());
  std::vector<LoopEdge> edges = edges_of(s);
  double R_before = 0.0, R_after = 0.0;
  for (const LoopEdge& e : edges) R_before += g.loop_residual_sq(e);
  const PoseGraphSolveReport r = g.solve(edges, LoopEdgeLoss::Plain);
  for (const LoopEdge& e : edges) R_after += g.loop_residual_sq(e);
  const double after = s.rmse(g.poses());
  WARN("pose graph, 24 exact loops: RMSE " << before << " m -> " << after << " m, end error " << s.end_error(s.odom)
                                           << " -> " << s.end_error(g.poses()) << " m; sum loop r^2 " << R_before
                                           << " -> " << R_after);
  CHECK(r.usable);
  CHECK(before > 1.0);
  CHECK(after < 0.35 * before);  // the odometry's 3 % scale error stays between loops
  CHECK(s.end_error(g.poses()) < 0.05 * s.end_error(s.odom));
  CHECK(R_after < 1e-3 * R_before);
  for (std::size_t k = 0; k < s.odom.size(); ++k) {
    CHECK(std::abs(pitch_of(g.pose(k).q) - pitch_of(s.odom[k].q)) < 1e-9);
    CHECK(std::abs(roll_of(g.pose(k).q) - roll_of(s.odom[k].q)) < 1e-9);
  }
  CHECK((g.pose(0).p - s.odom[0].p).norm() == 0.0);  // gauge
}

TEST_CASE("PoseGraph4Dof: a warm start from the solution stays there, in fewer iterations", "[loop][posegraph]") {
  LoopScenario s;
  for (int j = 0; j < 8; ++j) s.add_true_loops_in_group(j);
  const std::vector<LoopEdge> edges = edges_of(s);
  PoseGraph4Dof cold(s.odom);
  const PoseGraphSolveReport r_cold = cold.solve(edges, LoopEdgeLoss::Plain);
  PoseGraph4Dof warm(s.odom);
  for (std::size_t k = 0; k < s.odom.size(); ++k) {
    // set_estimate takes position and yaw only: the truth's roll and pitch must not leak in.
    warm.set_estimate(k, RigidPose{cold.pose(k).p, quat_from_ypr(yaw_of(cold.pose(k).q), 0.3, -0.2)});
    CHECK(std::abs(pitch_of(warm.pose(k).q) - pitch_of(s.odom[k].q)) < 1e-9);
    CHECK(std::abs(roll_of(warm.pose(k).q) - roll_of(s.odom[k].q)) < 1e-9);
  }
  const PoseGraphSolveReport r_warm = warm.solve(edges, LoopEdgeLoss::Plain);
  WARN("warm start at the solution: " << r_warm.iterations << " iterations (from the odometry " << r_cold.iterations
                                      << ")");
  CHECK(r_warm.iterations < r_cold.iterations);
  CHECK(r_warm.final_cost <= r_cold.final_cost * (1.0 + 1e-6));
  for (std::size_t k = 0; k < s.odom.size(); ++k) CHECK((warm.pose(k).p - cold.pose(k).p).norm() < 1e-4);
}

TEST_CASE("PoseGraph4Dof: loop residuals vanish at the truth and grow with the error", "[loop][posegraph]") {
  LoopScenario s(0.0, 1.0, 0.0);  // no drift: the odometry is the truth
  for (int j = 0; j < 8; ++j) s.add_true_loops_in_group(j);
  s.add_false_loop(150, Eigen::Vector3d(0.3, 0.0, 0.0));
  const PoseGraph4Dof g(s.odom);
  const std::vector<LoopEdge> edges = edges_of(s);
  for (std::size_t l = 0; l + 1 < edges.size(); ++l) CHECK(g.loop_residual_sq(edges[l]) < 1e-18);
  // 0.3 m of translation error at sigma 0.1 m: ||r||^2 = 9 (the false loop's yaw is right).
  CHECK(g.loop_residual_sq(edges.back()) == Approx(9.0).epsilon(1e-9));
}

TEST_CASE("PoseGraph4Dof: yaw across +-pi", "[loop][posegraph]") {
  // Three keyframes turning through 180 deg; the odometry's last yaw is 5 deg off; a loop from the last to
  // the first says where it really is. The solve must take the short way round the circle.
  std::vector<RigidPose> odom;
  odom.push_back(RigidPose{Eigen::Vector3d(0, 0, 0), quat_from_ypr(175.0 * kDeg, 0, 0)});
  odom.push_back(RigidPose{Eigen::Vector3d(-1, 0.1, 0), quat_from_ypr(179.0 * kDeg, 0, 0)});
  odom.push_back(RigidPose{Eigen::Vector3d(-2, 0.2, 0), quat_from_ypr(-172.0 * kDeg, 0, 0)});  // 13 deg past 175
  PoseGraph4Dof g(odom);
  RigidPose truth_last{Eigen::Vector3d(-2, 0.2, 0), quat_from_ypr(-177.0 * kDeg, 0, 0)};  // 8 deg past 175
  LoopEdge e{0, 2, compose(inverse(odom[0]), truth_last), 1.0};
  g.solve({e}, LoopEdgeLoss::Plain);
  const double yaw_last = yaw_of(g.pose(2).q);
  // Between the odometry's (-172) and the loop's (-177), never near 0.
  CHECK(normalize_angle(yaw_last - (-172.0 * kDeg)) < 0.0);
  CHECK(normalize_angle(yaw_last - (-177.0 * kDeg)) > -1e-6);
}

TEST_CASE("PoseGraph4Dof: Huber and switchable edges limit false loops", "[loop][posegraph]") {
  // Reference: the true loops alone. Then four consistent 2.5 m false loops in one lap-2 group.
  LoopScenario ref;
  for (int j = 0; j < 8; ++j) ref.add_true_loops_in_group(j);
  PoseGraph4Dof g_ref(ref.odom);
  g_ref.solve(edges_of(ref), LoopEdgeLoss::Plain);
  const double e_ref = ref.rmse(g_ref.poses());

  LoopScenario s = ref;
  s.add_false_loops_in_group(5, 4, Eigen::Vector3d(0.0, 2.5, 0.0));
  const std::vector<LoopEdge> edges = edges_of(s);
  PoseGraph4Dof plain(s.odom), huber(s.odom), sw(s.odom);
  plain.solve(edges, LoopEdgeLoss::Plain);
  huber.solve(edges, LoopEdgeLoss::Huber);
  std::vector<double> sv;
  sw.solve(edges, LoopEdgeLoss::Switchable, &sv);
  const double e_plain = s.rmse(plain.poses()), e_huber = s.rmse(huber.poses()), e_sw = s.rmse(sw.poses());
  REQUIRE(sv.size() == edges.size());
  double s_true_min = 1.0, s_false_max = 0.0;
  for (std::size_t l = 0; l < sv.size(); ++l) {
    CHECK(sv[l] >= 0.0);
    CHECK(sv[l] <= 1.0);
    if (s.loop_is_true[l]) s_true_min = std::min(s_true_min, sv[l]);
    else s_false_max = std::max(s_false_max, sv[l]);
  }
  WARN("four 2.5 m false loops, RMSE: true loops only " << e_ref << ", plain " << e_plain << ", huber " << e_huber
                                                        << ", switchable " << e_sw << " (true s >= " << s_true_min
                                                        << ", false s <= " << s_false_max << ")");
  CHECK(e_plain > 1.5 * e_ref);
  CHECK(e_huber < e_plain);
  CHECK(e_sw < 1.1 * e_ref);
  CHECK(s_true_min > 0.9);
  CHECK(s_false_max < 0.1);
}
