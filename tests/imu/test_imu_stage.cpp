// ImuStage: the yaml's noise read in both conventions, intervals identical to the builder's, counters,
// and new linearisation biases applied to the intervals that follow.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "sim/motion/imu_simulator.hpp"
#include "stages/imu/imu_stage.hpp"
#include "tests/imu/wavy_trajectory.hpp"

using namespace dynavins;

TEST_CASE("imu::ImuStageOptions reads the yaml noise as VINS-Fusion does, or as densities", "[imu][imu_stage]") {
  EstimatorOptions o;
  o.acc_n = 0.08;
  o.gyr_n = 0.004;
  o.acc_w = 0.00004;
  o.gyr_w = 2.0e-6;
  const imu::ImuStageOptions vins = imu::ImuStageOptions::from(o);
  CHECK(vins.noise.acc_n == 0.08);
  CHECK(vins.noise.gyr_w == 2.0e-6);
  CHECK(vins.imu_rate_hz == 200.0);
  const imu::ImuStageOptions dens = imu::ImuStageOptions::from(o, 400.0, imu::ImuNoiseConvention::ContinuousDensity);
  CHECK(dens.noise.acc_n == Approx(0.08 * std::sqrt(2.0 * 400.0)));
  CHECK(dens.noise.gyr_w == Approx(2.0e-6 * std::sqrt(400.0)));
  CHECK_THROWS_WITH(imu::ImuStageOptions::from(o, 0.0), Catch::Contains("IMU rate"));
}

TEST_CASE("imu::ImuStage emits one interval per frame pair and applies new biases to later intervals",
          "[imu][imu_stage]") {
  sim::ImuSimulatorOptions so;
  so.noise = sim::ImuNoiseModel::noise_free();
  const auto imu = sim::ImuSimulator(so).simulate(sim::wavy_trajectory(4.0), 1'900'000'000, 2'500'000'000).samples;
  imu::ImuStage stage{imu::ImuStageOptions{}};
  std::vector<PreintegratedInterval> out;
  const Eigen::Vector3d ba(0.01, -0.02, 0.03), bg(0.001, 0.002, -0.003);
  std::size_t next_imu = 0;
  int frames = 0;
  for (int64_t t = 2'000'000'000; t <= 2'400'000'000; t += 50'000'000) {
    // The replay order: IMU up to the frame time, then the frame.
    while (next_imu < imu.size() && imu[next_imu].t_ns <= t)
      for (auto& iv : stage.process(imu[next_imu++])) out.push_back(std::move(iv));
    if (t == 2'200'000'000) stage.set_biases(ba, bg);
    for (auto& iv : stage.process(imu::FrameTime{t})) out.push_back(std::move(iv));
    ++frames;
  }
  while (next_imu < imu.size())
    for (auto& iv : stage.process(imu[next_imu++])) out.push_back(std::move(iv));
  REQUIRE(out.size() == static_cast<std::size_t>(frames - 1));
  CHECK(stage.stats().frame_times == frames);
  CHECK(stage.stats().imu_samples == static_cast<int64_t>(imu.size()));
  CHECK(stage.stats().intervals == frames - 1);
  CHECK(stage.stats().bias_updates == 1);
  // Intervals are built when the IMU passes their end; those completed after set_biases use the new ones.
  int with_new_biases = 0;
  for (const auto& iv : out) {
    if (iv.preint.ba == ba && iv.preint.bg == bg) ++with_new_biases;
    else CHECK(iv.preint.ba.isZero());
  }
  CHECK(with_new_biases >= 3);
  CHECK(with_new_biases < frames - 1);
  stage.set_biases(ba, bg);  // unchanged: not counted
  CHECK(stage.stats().bias_updates == 1);
}
