// Every scenario in bench/scenarios/ loads, builds and renders, and does what its file says it does.
#include <filesystem>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "sim/scenario/scenario.hpp"

using namespace dynavins;
using namespace dynavins::sim;
namespace fs = std::filesystem;

namespace {

const fs::path kScenarios = fs::path(DYNAVINS_SOURCE_DIR) / "bench" / "scenarios";

/// Share of moving-object pixels of each frame of the first `seconds` (from `start`) of a scenario.
std::vector<double> moving_share(const std::string& name, double start, double seconds) {
  const auto spec = load_scenario((kScenarios / (name + ".yaml")).string());
  ScenarioSource src(build_scenario(spec, std::nullopt, start + seconds));
  std::vector<double> share;
  SensorEvent e;
  const int skip = static_cast<int>(start * 20);
  int frame = 0;
  while (src.next(e)) {
    if (const auto* f = std::get_if<StereoFrame>(&e)) {
      if (frame++ >= skip)
        share.push_back(static_cast<double>(cv::countNonZero(f->labels)) / static_cast<double>(f->labels.total()));
    }
  }
  return share;
}

}  // namespace

TEST_CASE("Every scenario file loads and its path builds", "[scenario][files]") {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(kScenarios)) {
    if (entry.path().extension() != ".yaml") continue;
    INFO(entry.path());
    const ScenarioSpec spec = load_scenario(entry.path().string());
    CHECK(spec.name == entry.path().stem().string());
    const auto body = build_body_trajectory(spec);
    CHECK(body->duration() >= 30.0);  // long enough for initialisation, windows and loops
    ++n;
  }
  CHECK(n >= 8);
}

TEST_CASE("The VIODE-like family shares one world and path and differs in traffic only", "[scenario][files]") {
  const auto none = load_scenario((kScenarios / "none.yaml").string());
  for (const char* level : {"low", "mid", "high", "night"}) {
    const auto s = load_scenario((kScenarios / (std::string(level) + ".yaml")).string());
    CHECK(s.waypoints == none.waypoints);
    CHECK(s.world_seed == none.world_seed);
    CHECK(s.seed == none.seed);
  }
  CHECK(none.objects.empty());
}

TEST_CASE("In `high` a truck covers most of the image for 1-3 s", "[scenario][files][heavy]") {
  // The first close crossing is scripted for t = 12 s.
  const auto share = moving_share("high", 10.0, 4.0);
  const auto covered = std::count_if(share.begin(), share.end(), [](double s) { return s > 0.5; });
  INFO("frames with more than half the image moving: " << covered);
  CHECK(covered >= 20);  // >= 1 s at 20 Hz
  CHECK(covered <= 60);  // <= 3 s
}
