// RunOutputs on hand-made estimates: ground truth written and ATE computed (zero for an exactly rotated
// and shifted copy of the truth), nothing final-looking before complete(), stale results removed.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "eval/trajectory_io.hpp"
#include "pipeline/vio/run_outputs.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;
namespace fs = std::filesystem;

namespace {

std::string fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("dynavins_test_outputs_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d.string();
}

GroundTruthState truth_at(int k) {
  GroundTruthState g;
  g.t_ns = 1'000'000'000 + k * 50'000'000LL;
  const double t = 0.05 * k;
  g.p_wb = Eigen::Vector3d(std::sin(t), 0.5 * std::cos(0.7 * t), 0.1 * t);
  g.q_wb = Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d(0.2, 0.3, 0.9).normalized()));
  return g;
}

}  // namespace

TEST_CASE("RunOutputs writes ground truth and an SE3 ATE of zero for a rigidly moved copy", "[vio][outputs]") {
  const std::string dir = fresh_dir("ate");
  RunOutputs out(dir);
  VioRunResult run;
  run.report.ok = true;
  const Eigen::Quaterniond R(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d t(3, -2, 1);
  for (int k = 0; k < 40; ++k) {
    run.ground_truth.push_back(truth_at(k));
    estimator::WindowEstimate e;
    e.t_ns = truth_at(k).t_ns;
    e.seq = k;
    e.status = k < 5 ? estimator::EstimatorStatus::Initializing : estimator::EstimatorStatus::Tracking;
    e.state.p_wb = R * truth_at(k).p_wb + t;
    e.state.q_wb = R * truth_at(k).q_wb;
    e.solve.alternations = k < 5 ? 0 : 2;
    e.solve.ba_ms = k;
    if (k == 5) e.event = "initialized, \"quoted\"";
    out.write(e);
  }
  CHECK_FALSE(fs::exists(dir + "/odometry.tum"));  // nothing looks complete before complete()
  CHECK(fs::exists(dir + "/odometry.tum.partial"));
  out.complete(run, RunDescription{"cfg.yaml", "test", "huber", false, 0.0});

  REQUIRE(out.ate().evaluated);
  CHECK(out.ate().se3_m < 1e-6);
  CHECK(out.ate().sim3_m < 1e-6);
  CHECK(out.ate().matched == 35);
  const eval::Trajectory gt = eval::read_trajectory(dir + "/groundtruth.tum");
  CHECK(gt.size() == 40);
  const eval::Trajectory est = eval::read_trajectory(dir + "/odometry.tum");
  REQUIRE(est.size() == 35);
  CHECK(est.poses[0].t_ns == truth_at(5).t_ns);
  const std::string j = out.summary_json();
  CHECK(j.find("\"ate_se3_m\": ") != std::string::npos);
  CHECK(j.find("\"ba_solves\": 35,") != std::string::npos);
  CHECK(j.find("\"ba_ms_max\": 39,") != std::string::npos);
  CHECK(j.find("\"ba_ms_p95\": 38,") != std::string::npos);  // nearest rank of 5..39
  CHECK(j.find("\"alternations_mean\": 2,") != std::string::npos);
  CHECK(j.find("\"cameras\": \"mono\"") != std::string::npos);
  std::ifstream ev(dir + "/estimator_events.csv");
  std::string header, line;
  std::getline(ev, header);
  std::getline(ev, line);
  CHECK(line == std::to_string(truth_at(5).t_ns) + ",5,\"initialized, \"\"quoted\"\"\"");
  for (const auto& f : fs::directory_iterator(dir)) CHECK(f.path().extension() != ".partial");
  fs::remove_all(dir);
}

TEST_CASE("RunOutputs removes an earlier run's results so a failed run leaves nothing final", "[vio][outputs]") {
  const std::string dir = fresh_dir("stale");
  fs::create_directories(dir);
  std::ofstream(dir + "/summary.json") << "{}\n";
  std::ofstream(dir + "/odometry.tum") << "1 0 0 0 0 0 0 1\n";
  {
    RunOutputs out(dir);
    estimator::WindowEstimate e;
    e.status = estimator::EstimatorStatus::Tracking;
    out.write(e);
  }  // destroyed without complete(): the run failed
  CHECK_FALSE(fs::exists(dir + "/summary.json"));
  CHECK_FALSE(fs::exists(dir + "/odometry.tum"));
  CHECK(fs::exists(dir + "/odometry.tum.partial"));
  fs::remove_all(dir);
}

TEST_CASE("RunOutputs names the directory it cannot create", "[vio][outputs]") {
  const std::string file = fresh_dir("file");
  std::ofstream(file) << "x";
  CHECK_THROWS_WITH(RunOutputs(file + "/sub"), Catch::Contains(file));
  fs::remove(file);
}
