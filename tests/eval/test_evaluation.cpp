// evaluate(): the evo known answers on the TUM RGB-D fr1/xyz fixture (see
// ../shared/data/trajectories/README.md, evo v1.36.5), plus the alignment name parser.
#include "eval/evaluation.hpp"
#include "eval/trajectory_io.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace dynavins::eval;

namespace {

const std::string kFixture = std::string(DYNAVINS_SHARED_DIR) + "/data/trajectories/evo_fixture/";

EvalResult run_fixture(Alignment align) {
  const Trajectory gt = read_trajectory(kFixture + "freiburg1_xyz-groundtruth.txt");
  const Trajectory est = read_trajectory(kFixture + "freiburg1_xyz-rgbdslam_drift.txt");
  EvalOptions o;
  o.align = align;
  return evaluate(gt, est, o);
}

constexpr double kTol = 1e-5;  // metres; evo prints 6 decimals

}  // namespace

TEST_CASE("evaluate matches evo_ape without alignment", "[eval][evo]") {
  const EvalResult r = run_fixture(Alignment::None);
  CHECK(r.association.size() == 785);
  CHECK(r.ate.count == 785);
  CHECK(r.ate.rmse == Approx(0.134185).margin(kTol));
  CHECK(r.ate.mean == Approx(0.122986).margin(kTol));
  CHECK(r.ate.max == Approx(0.249332).margin(kTol));
  CHECK(r.alignment.s == 1.0);
  CHECK(r.alignment.R.isIdentity(0.0));
}

TEST_CASE("evaluate matches evo_ape -a (SE3 Umeyama)", "[eval][evo]") {
  const EvalResult r = run_fixture(Alignment::SE3);
  CHECK(r.association.size() == 785);
  CHECK(r.ate.rmse == Approx(0.013470).margin(kTol));
  CHECK(r.ate.mean == Approx(0.012025).margin(kTol));
  CHECK(r.ate.max == Approx(0.034760).margin(kTol));
  CHECK(r.alignment.s == 1.0);
}

TEST_CASE("evaluate matches evo_ape -as (Sim3 Umeyama)", "[eval][evo]") {
  const EvalResult r = run_fixture(Alignment::Sim3);
  CHECK(r.association.size() == 785);
  CHECK(r.ate.rmse == Approx(0.013389).margin(kTol));
  CHECK(r.ate.mean == Approx(0.011987).margin(kTol));
  CHECK(r.ate.max == Approx(0.034846).margin(kTol));
  CHECK(r.alignment.s == Approx(1.0080013).margin(1e-7));
}

TEST_CASE("evaluate matches evo_rpe -a (delta 1 frame, translation)", "[eval][evo]") {
  const EvalResult r = run_fixture(Alignment::SE3);
  CHECK(r.rpe.count == 784);  // consecutive pairs of 785 associated poses
  CHECK(r.rpe.rmse == Approx(0.005764).margin(kTol));
  // A rigid alignment cannot change relative motion, so the unaligned RPE is the same.
  const EvalResult raw = run_fixture(Alignment::None);
  CHECK(raw.rpe.rmse == Approx(r.rpe.rmse).margin(1e-12));
}

TEST_CASE("evaluate with a larger RPE delta uses every delta-th associated pose", "[eval]") {
  const Trajectory gt = read_trajectory(kFixture + "freiburg1_xyz-groundtruth.txt");
  const Trajectory est = read_trajectory(kFixture + "freiburg1_xyz-rgbdslam_drift.txt");
  EvalOptions o;
  o.rpe_delta = 10;
  const EvalResult r = evaluate(gt, est, o);
  CHECK(r.rpe.count == 78);  // indices 0, 10, ..., 780
  o.rpe_delta = 785;
  CHECK_THROWS_AS(evaluate(gt, est, o), std::invalid_argument);
}

TEST_CASE("evaluate of a trajectory against itself is zero under every alignment", "[eval]") {
  const Trajectory gt = read_trajectory(kFixture + "freiburg1_xyz-groundtruth.txt");
  for (Alignment a : {Alignment::None, Alignment::SE3, Alignment::Sim3}) {
    const EvalResult r = evaluate(gt, gt, EvalOptions{a, 0.01, 1});
    CHECK(r.association.size() == gt.size());
    CHECK(r.ate.max < 1e-9);
    CHECK(r.rpe.max < 1e-9);
  }
}

TEST_CASE("transformed applies a similarity to positions and orientations", "[eval]") {
  Trajectory t;
  t.source = "mem";
  StampedPose p;
  p.p = {1, 0, 0};
  t.poses.push_back(p);
  Similarity3 T;
  T.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.t = {0, 0, 1};
  T.s = 2.0;
  const Trajectory out = transformed(t, T);
  CHECK((out.poses[0].p - Eigen::Vector3d(0, 2, 1)).norm() < 1e-12);
  CHECK(out.poses[0].q.angularDistance(Eigen::Quaterniond(T.R)) < 1e-12);
}

TEST_CASE("parse_alignment accepts the three names and rejects others", "[eval]") {
  CHECK(parse_alignment("se3") == Alignment::SE3);
  CHECK(parse_alignment("SIM3") == Alignment::Sim3);
  CHECK(parse_alignment("none") == Alignment::None);
  CHECK(std::string(alignment_name(Alignment::Sim3)) == "sim3");
  CHECK_THROWS_WITH(parse_alignment("sim2"), Catch::Contains("sim2"));
}
