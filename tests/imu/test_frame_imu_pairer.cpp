// FrameImuPairer: time-ordered pairing whatever the interleaving, merging over dropped frames (equal to an
// interval built directly over the longer span), gap propagation, start-up discards, unpaired frames counted.
#include <catch2/catch.hpp>

#include <algorithm>
#include <set>
#include <vector>

#include "sim/motion/imu_simulator.hpp"
#include "stages/imu/frame_imu_pairer.hpp"
#include "stages/imu/imu_interval_builder.hpp"
#include "tests/imu/wavy_trajectory.hpp"

using namespace dynavins;

namespace {

constexpr int64_t kFrameStart = 2'000'000'000, kFramePeriod = 50'000'000;

std::vector<ImuSample> imu_samples() {
  sim::ImuSimulatorOptions o;
  o.noise = sim::ImuNoiseModel::noise_free();
  return sim::ImuSimulator(o).simulate(sim::wavy_trajectory(4.0), 1'900'000'000, 2'700'000'000).samples;
}

// Source frame times on the 200 Hz IMU grid, so that a merged interval and a direct one use the same samples.
std::vector<int64_t> source_frame_times(int n = 12) {
  std::vector<int64_t> t;
  for (int k = 0; k < n; ++k) t.push_back(kFrameStart + k * kFramePeriod);
  return t;
}

std::vector<PreintegratedInterval> intervals_for(const std::vector<ImuSample>& imu, const std::vector<int64_t>& frames) {
  imu::ImuIntervalBuilder b;
  std::vector<PreintegratedInterval> out;
  for (int64_t t : frames)
    for (auto& iv : b.add_frame(t)) out.push_back(std::move(iv));
  for (const ImuSample& s : imu)
    for (auto& iv : b.add_imu(s)) out.push_back(std::move(iv));
  return out;
}

TrackedFrame frame_at(int64_t t, int64_t seq) {
  TrackedFrame f;
  f.t_ns = t;
  f.seq = seq;
  return f;
}

void append(std::vector<imu::FrameWithImu>& out, std::vector<imu::FrameWithImu> more) {
  for (auto& f : more) out.push_back(std::move(f));
}

void require_same_deltas(const PreintegratedInterval& a, const PreintegratedInterval& b) {
  REQUIRE(a.t_begin_ns == b.t_begin_ns);
  REQUIRE(a.t_end_ns == b.t_end_ns);
  CHECK((a.preint.alpha - b.preint.alpha).norm() < 1e-9);
  CHECK((a.preint.beta - b.preint.beta).norm() < 1e-9);
  CHECK(a.preint.gamma.angularDistance(b.preint.gamma) < 1e-9);
  CHECK((a.preint.covariance - b.preint.covariance).cwiseAbs().maxCoeff() < 1e-9);
  CHECK((a.preint.jacobian - b.preint.jacobian).cwiseAbs().maxCoeff() < 1e-9);
  CHECK(a.preint.sum_dt == Approx(b.preint.sum_dt).margin(1e-12));
  CHECK(a.num_raw_samples == b.num_raw_samples);
  CHECK(a.has_gap == b.has_gap);
  CHECK(a.max_gap_ns == b.max_gap_ns);
}

}  // namespace

TEST_CASE("frames and intervals delivered in order pair one to one", "[imu][pairer]") {
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu_samples(), times);
  REQUIRE(intervals.size() == times.size() - 1);
  imu::FrameImuPairer p;
  std::vector<imu::FrameWithImu> out;
  for (std::size_t k = 0; k < times.size(); ++k) {
    append(out, p.add_frame(frame_at(times[k], static_cast<int64_t>(k))));
    if (k > 0) append(out, p.add_interval(intervals[k - 1]));
    CHECK(out.size() == k + 1);  // each frame leaves as soon as its interval is there
  }
  REQUIRE(out.size() == times.size());
  CHECK_FALSE(out[0].imu.has_value());
  for (std::size_t k = 1; k < out.size(); ++k) {
    REQUIRE(out[k].imu.has_value());
    require_same_deltas(*out[k].imu, intervals[k - 1]);
  }
  CHECK(p.stats().emitted == static_cast<int64_t>(times.size()));
  CHECK(p.stats().merged_intervals == 0);
}

TEST_CASE("the output does not depend on which thread delivered first", "[imu][pairer]") {
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu_samples(), times);

  SECTION("all frames first, then the IMU") {
    imu::FrameImuPairer p;
    std::vector<imu::FrameWithImu> out;
    for (std::size_t k = 0; k < times.size(); ++k) append(out, p.add_frame(frame_at(times[k], k)));
    CHECK(out.size() == 1);  // only the first frame, which needs no IMU
    for (const auto& iv : intervals) append(out, p.add_interval(iv));
    REQUIRE(out.size() == times.size());
    for (std::size_t k = 1; k < out.size(); ++k) require_same_deltas(*out[k].imu, intervals[k - 1]);
  }
  SECTION("all IMU first, then the frames") {
    imu::FrameImuPairer p;
    std::vector<imu::FrameWithImu> out;
    for (const auto& iv : intervals) append(out, p.add_interval(iv));
    CHECK(out.empty());
    for (std::size_t k = 0; k < times.size(); ++k) {
      append(out, p.add_frame(frame_at(times[k], k)));
      CHECK(out.size() == k + 1);
    }
    for (std::size_t k = 1; k < out.size(); ++k) require_same_deltas(*out[k].imu, intervals[k - 1]);
  }
}

TEST_CASE("frames dropped by the tracker: the merged interval equals one built over the longer span",
          "[imu][pairer]") {
  const auto imu = imu_samples();
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu, times);
  const std::set<std::size_t> dropped{2, 3, 6, 9};
  std::vector<int64_t> kept;
  for (std::size_t k = 0; k < times.size(); ++k)
    if (!dropped.count(k)) kept.push_back(times[k]);
  const auto direct = intervals_for(imu, kept);

  imu::FrameImuPairer p;
  std::vector<imu::FrameWithImu> out;
  // Interleaved the other way round from real life too: IMU half a frame ahead.
  std::size_t next_interval = 0;
  for (std::size_t k = 0; k < times.size(); ++k) {
    while (next_interval < intervals.size() && intervals[next_interval].t_end_ns <= times[k] + kFramePeriod)
      append(out, p.add_interval(intervals[next_interval++]));
    if (!dropped.count(k)) append(out, p.add_frame(frame_at(times[k], k)));
  }
  REQUIRE(out.size() == kept.size());
  CHECK_FALSE(out[0].imu.has_value());
  for (std::size_t k = 1; k < out.size(); ++k) {
    CHECK(out[k].frame.t_ns == kept[k]);
    REQUIRE(out[k].imu.has_value());
    require_same_deltas(*out[k].imu, direct[k - 1]);
  }
  CHECK(p.stats().merged_intervals == static_cast<int64_t>(dropped.size()));
}

TEST_CASE("an IMU gap in any merged piece flags the merged interval", "[imu][pairer]") {
  auto imu = imu_samples();
  const auto times = source_frame_times();
  // Remove 40 ms of IMU inside source interval (times[3], times[4]].
  const int64_t gap_from = times[3] + 5'000'000, gap_to = times[3] + 45'000'000;
  imu.erase(std::remove_if(imu.begin(), imu.end(), [&](const ImuSample& s) { return s.t_ns > gap_from && s.t_ns < gap_to; }),
            imu.end());
  const auto intervals = intervals_for(imu, times);
  REQUIRE(intervals[3].has_gap);
  imu::FrameImuPairer p;
  std::vector<imu::FrameWithImu> out;
  for (std::size_t k = 0; k < times.size(); ++k)
    if (k != 3 && k != 4) append(out, p.add_frame(frame_at(times[k], k)));  // frames 3 and 4 dropped
  for (const auto& iv : intervals) append(out, p.add_interval(iv));
  REQUIRE(out.size() == times.size() - 2);
  const imu::FrameWithImu& f5 = out[3];  // frames 0 1 2 5
  REQUIRE(f5.frame.t_ns == times[5]);
  REQUIRE(f5.imu.has_value());
  CHECK(f5.imu->has_gap);
  CHECK(f5.imu->max_gap_ns == gap_to - gap_from);
  CHECK(f5.imu->num_raw_samples == intervals[2].num_raw_samples + intervals[3].num_raw_samples +
                                       intervals[4].num_raw_samples);
  CHECK_FALSE(out[2].imu->has_gap);  // frame 2's own interval is clean
}

TEST_CASE("intervals before the first tracked frame are discarded", "[imu][pairer]") {
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu_samples(), times);
  imu::FrameImuPairer p;
  std::vector<imu::FrameWithImu> out;
  for (const auto& iv : intervals) append(out, p.add_interval(iv));
  for (std::size_t k = 3; k < times.size(); ++k) append(out, p.add_frame(frame_at(times[k], k)));
  REQUIRE(out.size() == times.size() - 3);
  CHECK(out[0].frame.t_ns == times[3]);
  CHECK_FALSE(out[0].imu.has_value());
  REQUIRE(out[1].imu.has_value());
  require_same_deltas(*out[1].imu, intervals[3]);
  CHECK(p.stats().intervals_discarded == 3);
}

TEST_CASE("frames the IMU never reached are counted at finish, not emitted", "[imu][pairer]") {
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu_samples(), times);
  imu::FrameImuPairer p;
  std::vector<imu::FrameWithImu> out;
  for (std::size_t k = 0; k < times.size(); ++k) append(out, p.add_frame(frame_at(times[k], k)));
  for (std::size_t k = 0; k + 4 < intervals.size(); ++k) append(out, p.add_interval(intervals[k]));  // IMU stops early
  const std::size_t waiting = p.waiting_frames();
  CHECK(waiting == 4);
  p.finish();
  CHECK(p.stats().unpaired_at_finish == 4);
  CHECK(p.waiting_frames() == 0);
  CHECK(p.stats().emitted + p.stats().unpaired_at_finish == static_cast<int64_t>(times.size()));
  CHECK(out.size() == times.size() - 4);
}

TEST_CASE("frames that no interval boundary matches are skipped or restarted, and counted", "[imu][pairer]") {
  const auto times = source_frame_times();
  const auto intervals = intervals_for(imu_samples(), times);

  SECTION("a frame time inside an interval is skipped; its IMU goes to the next frame") {
    imu::FrameImuPairer p;
    std::vector<imu::FrameWithImu> out;
    append(out, p.add_frame(frame_at(times[0], 0)));
    append(out, p.add_frame(frame_at(times[1] + 10'000'000, 1)));  // no source frame there
    append(out, p.add_frame(frame_at(times[2], 2)));
    for (std::size_t k = 0; k < 2; ++k) append(out, p.add_interval(intervals[k]));
    REQUIRE(out.size() == 2);
    CHECK(out[1].frame.t_ns == times[2]);
    REQUIRE(out[1].imu.has_value());
    CHECK(out[1].imu->t_begin_ns == times[0]);
    CHECK(p.stats().skipped_inside_interval == 1);
  }
  SECTION("a hole in the interval stream restarts without IMU") {
    imu::FrameImuPairer p;
    std::vector<imu::FrameWithImu> out;
    for (std::size_t k = 0; k < 5; ++k) append(out, p.add_frame(frame_at(times[k], k)));
    append(out, p.add_interval(intervals[0]));
    append(out, p.add_interval(intervals[2]));  // (times[2], times[3]]: nothing connects frame 1 to 2
    append(out, p.add_interval(intervals[3]));
    REQUIRE(out.size() == 5);  // frames 0, 1, 2 (restart without IMU), 3, 4
    CHECK(out[1].imu.has_value());
    CHECK_FALSE(out[2].imu.has_value());
    REQUIRE(out[3].imu.has_value());
    CHECK(out[3].imu->t_begin_ns == times[2]);
    REQUIRE(out[4].imu.has_value());
    CHECK(out[4].imu->t_begin_ns == times[3]);
    CHECK(p.stats().restarted_without_imu == 1);
  }
}
