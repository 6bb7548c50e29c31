// associate(): evo's nearest-stamp rule, its tolerance, tie-breaking and failure modes.
#include "eval/association.hpp"
#include "eval/trajectory_io.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace dynavins::eval;

namespace {

Trajectory at_times(const std::string& name, std::initializer_list<double> times) {
  Trajectory t;
  t.source = name;
  for (double s : times) {
    StampedPose p;
    p.t = s;
    p.t_ns = std::llround(s * 1e9);
    t.poses.push_back(p);
  }
  return t;
}

}  // namespace

TEST_CASE("associate pairs 785 poses on the evo fixture", "[eval][association]") {
  const std::string dir = std::string(DYNAVINS_SHARED_DIR) + "/data/trajectories/evo_fixture/";
  const Trajectory gt = read_trajectory(dir + "freiburg1_xyz-groundtruth.txt");
  const Trajectory est = read_trajectory(dir + "freiburg1_xyz-rgbdslam_drift.txt");
  const Association a = associate(gt, est, 0.01);
  REQUIRE(a.size() == 785);
  REQUIRE(a.est_index.size() == 785);
  for (std::size_t k = 0; k < a.size(); ++k) {
    CHECK(std::fabs(gt.poses[a.gt_index[k]].t - est.poses[a.est_index[k]].t) <= 0.01);
    if (k > 0) {
      CHECK(a.est_index[k] > a.est_index[k - 1]);  // estimate is the shorter one: each pose at most once
    }
  }
  // A tighter tolerance can only lose pairs.
  CHECK(associate(gt, est, 0.005).size() < 785);
}

TEST_CASE("associate iterates the shorter trajectory and takes the nearest stamp", "[eval][association]") {
  const Trajectory gt = at_times("gt", {0.00, 0.01, 0.02, 0.03, 0.04, 0.05});
  const Trajectory est = at_times("est", {0.012, 0.029, 0.5});
  const Association a = associate(gt, est, 0.005);
  REQUIRE(a.size() == 2);  // 0.5 has no partner
  CHECK(a.est_index == std::vector<std::size_t>{0, 1});
  CHECK(a.gt_index == std::vector<std::size_t>{1, 3});

  // Roles swap when the estimate is longer: pairs still report (gt, est) indices.
  const Association b = associate(est, gt, 0.005);
  CHECK(b.gt_index == std::vector<std::size_t>{0, 1});
  CHECK(b.est_index == std::vector<std::size_t>{1, 3});
}

TEST_CASE("associate breaks exact ties towards the earlier stamp, as np.argmin", "[eval][association]") {
  const Trajectory gt = at_times("gt", {1.0, 2.0, 3.0, 4.0});
  const Trajectory est = at_times("est", {2.5});
  const Association a = associate(gt, est, 0.6);
  REQUIRE(a.size() == 1);
  CHECK(a.gt_index[0] == 1);
}

TEST_CASE("associate accepts |dt| equal to max_dt and handles stamps outside the range", "[eval][association]") {
  const Trajectory gt = at_times("gt", {0.0, 1.0, 2.0});
  const Trajectory est = at_times("est", {-0.25, 2.25});
  CHECK(associate(gt, est, 0.25).size() == 2);
  CHECK_THROWS_WITH(associate(gt, est, 0.2499), Catch::Contains("est") && Catch::Contains("gt"));
}

TEST_CASE("associate rejects bad arguments", "[eval][association]") {
  const Trajectory gt = at_times("gt", {0.0, 1.0});
  CHECK_THROWS_AS(associate(gt, gt, -0.1), std::invalid_argument);
  CHECK_THROWS_AS(associate(gt, gt, std::nan("")), std::invalid_argument);
  CHECK_THROWS_AS(associate(gt, at_times("empty", {}), 0.01), std::runtime_error);
  CHECK_THROWS_WITH(associate(gt, at_times("unsorted", {1.0, 0.0}), 0.01), Catch::Contains("unsorted"));
}
