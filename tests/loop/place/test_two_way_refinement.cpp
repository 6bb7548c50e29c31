// refine_two_way: with both keyframes' 3-D points (independent depth errors) the relative pose is closer to
// the truth than with the match keyframe's points alone (what PnP uses); too few correspondences leave it.
#include <catch2/catch.hpp>

#include <random>

#include "stages/loop/place/two_way_refinement.hpp"

using namespace dynavins::loop;

namespace {

struct Trial {
  std::vector<TwoWayCorrespondence> c;
  Eigen::Quaterniond q_true;
  Eigen::Vector3d t_true;
};

// 20 points 4-8 m ahead of C_m; C_k 0.5 m aside and turned 5 deg; each keyframe's 3-D points with 3 %
// depth error along its own rays (stereo at these depths), pixels with 0.3 px noise.
Trial make_trial(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(4.0, 8.0);
  std::normal_distribution<double> depth_err(0.0, 0.03), px(0.0, 0.3 / 460.0);
  Trial tr;
  tr.q_true = Eigen::Quaterniond(Eigen::AngleAxisd(5.0 * M_PI / 180, Eigen::Vector3d::UnitY()));
  tr.t_true = Eigen::Vector3d(0.5, 0.05, -0.2);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d P_m = depth(rng) * Eigen::Vector3d(0.6 * u(rng), 0.4 * u(rng), 1.0);
    const Eigen::Vector3d P_k = tr.q_true * P_m + tr.t_true;
    TwoWayCorrespondence x;
    x.p_m = P_m * (1.0 + depth_err(rng));
    x.p_k = P_k * (1.0 + depth_err(rng));
    x.has_p_k = true;
    x.xy_k = P_k.head<2>() / P_k.z() + Eigen::Vector2d(px(rng), px(rng));
    x.xy_m = P_m.head<2>() / P_m.z() + Eigen::Vector2d(px(rng), px(rng));
    tr.c.push_back(x);
  }
  return tr;
}

}  // namespace

TEST_CASE("two-way refinement: both keyframes' points beat the match's alone", "[loop][place]") {
  std::mt19937 rng(3);
  double one_way = 0.0, two_way = 0.0;
  const int trials = 30;
  for (int k = 0; k < trials; ++k) {
    Trial tr = make_trial(rng);
    Eigen::Quaterniond q1 = tr.q_true, q2 = tr.q_true;  // start at the truth: only the minimum differs
    Eigen::Vector3d t1 = tr.t_true, t2 = tr.t_true;
    std::vector<TwoWayCorrespondence> match_only = tr.c;
    for (auto& x : match_only) x.has_p_k = false;
    REQUIRE(refine_two_way(match_only, q1, t1));
    REQUIRE(refine_two_way(tr.c, q2, t2));
    one_way += (t1 - tr.t_true).norm();
    two_way += (t2 - tr.t_true).norm();
  }
  INFO("mean translation error: match points only " << one_way / trials << " m, both " << two_way / trials << " m");
  // Independent depth errors on twice the points: about 1/sqrt(2) of the error; 0.85 leaves margin.
  CHECK(two_way < 0.85 * one_way);
}

TEST_CASE("two-way refinement leaves the pose alone with fewer than 3 correspondences", "[loop][place]") {
  std::mt19937 rng(4);
  Trial tr = make_trial(rng);
  tr.c.resize(2);
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t(1, 2, 3);
  CHECK_FALSE(refine_two_way(tr.c, q, t));
  CHECK(t == Eigen::Vector3d(1, 2, 3));
  CHECK(q.coeffs() == Eigen::Quaterniond::Identity().coeffs());
}
