// LcmPublisher on memq://: what a subscriber receives for each kind of item, the status rule (a change
// at once, otherwise once a second with the reason of the change), the latency it measures, and the
// channel-name overrides.
#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/pose_t.hpp>
#include <dynavins_lcm/status_t.hpp>
#include <dynavins_lcm/weighted_feature_set_t.hpp>

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "pipeline/clock.hpp"
#include "pipeline/lcm_publisher.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

/// Every message received, decoded by channel.
struct Recorder {
  std::map<std::string, int> count;
  std::vector<dynavins_lcm::pose_t> poses;
  std::vector<dynavins_lcm::status_t> status;
  std::vector<dynavins_lcm::weighted_feature_set_t> features;
  dynavins_lcm::path_t path;
  dynavins_lcm::loop_hypotheses_t hypotheses;
  void on(const lcm::ReceiveBuffer* rb, const std::string& ch) {
    ++count[ch];
    if (ch == "P" || ch == "P_IMU") {
      dynavins_lcm::pose_t m;
      REQUIRE(m.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0);
      poses.push_back(m);
    } else if (ch == "S") {
      dynavins_lcm::status_t m;
      REQUIRE(m.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0);
      status.push_back(m);
    } else if (ch == "PATH") {
      REQUIRE(path.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0);
    } else if (ch == "LOOPS") {
      REQUIRE(hypotheses.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0);
    } else if (ch == "F") {
      dynavins_lcm::weighted_feature_set_t m;
      REQUIRE(m.decode(rb->data, 0, static_cast<int>(rb->data_size)) > 0);
      features.push_back(m);
    }
  }
};

PublisherChannels test_channels() {
  PublisherChannels c;
  for (const char* a : {"pose_imu=P_IMU", "pose=P", "features=F", "status=S", "stats=ST"}) c.set(a);
  return c;
}

void drain(lcm::LCM& lcm) {
  while (lcm.handleTimeout(0) > 0) {
  }
}

StatusUpdate status(int64_t t_ns, estimator::EstimatorStatus s, std::string reason = "") {
  return StatusUpdate{t_ns, s, std::move(reason), 1, 0};
}

}  // namespace

TEST_CASE("LcmPublisher: each item reaches its channel, decoded as sent", "[lcm_publisher]") {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  Recorder rx;
  lcm.subscribe(".*", &Recorder::on, &rx);
  LcmPublisher pub(lcm, test_channels());

  NavState s;
  s.t_ns = 1'000'000'000;
  s.p_wb = {1, 2, 3};
  pub.process(PublishItem{steady_now_ns(), PoseEstimate{PoseSource::ImuRate, s}});
  s.t_ns += 50'000'000;
  pub.process(PublishItem{steady_now_ns(), PoseEstimate{PoseSource::Window, s}});
  WeightedFeatureSet set;
  set.t_ns = s.t_ns;
  set.features.resize(3);
  set.features[1].weight = 0.25f;
  pub.process(PublishItem{0, set});
  drain(lcm);

  CHECK(rx.count["P_IMU"] == 1);
  CHECK(rx.count["P"] == 1);
  REQUIRE(rx.features.size() == 1);
  CHECK(rx.features[0].num_features == 3);
  CHECK(rx.features[0].features[1].weight == 0.25f);
  REQUIRE(rx.poses.size() == 2);
  CHECK(rx.poses[0].source == dynavins_lcm::pose_t::SOURCE_IMU_RATE);
  CHECK(rx.poses[1].source == dynavins_lcm::pose_t::SOURCE_WINDOW);
  CHECK(rx.poses[1].utime == 1'050'000);
  CHECK(rx.poses[1].position[2] == 3.0);

  const PublisherStats st = pub.stats();
  CHECK(st.imu_poses == 1);
  CHECK(st.window_poses == 1);
  CHECK(st.feature_sets == 1);
  CHECK(st.imu_pose_latency.count == 1);
  CHECK(st.window_pose_latency.count == 1);
  CHECK(st.failed == 0);
}

TEST_CASE("LcmPublisher: a status change goes out at once, a repeat does not", "[lcm_publisher]") {
  lcm::LCM lcm("memq://");
  Recorder rx;
  lcm.subscribe(".*", &Recorder::on, &rx);
  LcmPublisher pub(lcm, test_channels(), [] { return RunReport{}; });
  using estimator::EstimatorStatus;
  pub.process(PublishItem{0, status(1, EstimatorStatus::Initializing)});
  pub.process(PublishItem{0, status(2, EstimatorStatus::Initializing)});  // no change: not sent yet
  pub.process(PublishItem{0, status(3, EstimatorStatus::Tracking, "initialized")});
  pub.process(PublishItem{0, status(4, EstimatorStatus::Tracking)});
  pub.process(PublishItem{0, status(5, EstimatorStatus::Reset, "reset: too few features")});
  drain(lcm);
  REQUIRE(rx.status.size() == 3);
  CHECK(rx.status[0].status == dynavins_lcm::status_t::INITIALIZING);
  CHECK(rx.status[1].status == dynavins_lcm::status_t::TRACKING);
  CHECK(rx.status[1].reason == "initialized");
  CHECK(rx.status[2].status == dynavins_lcm::status_t::RESET);

  // The end of the run: the current status with the reason of the change that led to it, and stats.
  pub.process(PublishItem{0, status(6, EstimatorStatus::Reset)});
  pub.finish();
  drain(lcm);
  REQUIRE(rx.status.size() == 4);
  CHECK(rx.status[3].utime == 0);  // 6 ns rounds to 0 us
  CHECK(rx.status[3].reason == "reset: too few features");
  CHECK(rx.count["ST"] == 1);
}

TEST_CASE("PublisherChannels: key=NAME overrides, bad keys are named", "[lcm_publisher]") {
  PublisherChannels c;
  CHECK(c.pose == "DYNAVINS_POSE");
  c.set("pose=ROBOT_POSE");
  CHECK(c.pose == "ROBOT_POSE");
  CHECK_THROWS_WITH(c.set("posture=X"), Catch::Contains("posture") && Catch::Contains("pose_imu"));
  CHECK_THROWS_WITH(c.set("pose="), Catch::Contains("key=NAME"));
  CHECK_THROWS_WITH(c.set("pose"), Catch::Contains("key=NAME"));
}

TEST_CASE("LcmPublisher: loop outputs (corrected pose, path, hypotheses) reach their channels", "[lcm_publisher]") {
  lcm::LCM lcm("memq://");
  Recorder rx;
  lcm.subscribe(".*", &Recorder::on, &rx);
  PublisherChannels c = test_channels();
  c.set("pose_corrected=PC");
  c.set("path=PATH");
  c.set("loops=LOOPS");
  LcmPublisher pub(lcm, c);
  NavState s;
  s.t_ns = 2'000'000'000;
  pub.process(PublishItem{0, PoseEstimate{PoseSource::LoopCorrected, s}});
  PathUpdate path;
  path.t_ns = s.t_ns;
  path.poses.assign(3, PoseEstimate{PoseSource::LoopCorrected, s});
  pub.process(PublishItem{0, path});
  HypothesesUpdate h;
  h.t_ns = s.t_ns;
  h.group_first_t_ns = 1'000'000'000;
  h.group_size = 9;
  h.hypotheses.resize(2);
  h.hypotheses[0].weight = 0.97f;
  h.hypotheses[0].loops = {{1'500'000'000, 100'000'000}, {1'550'000'000, 150'000'000}};
  h.hypotheses[1].weight = 0.01f;
  h.hypotheses[1].loops = {{1'600'000'000, 900'000'000}};
  pub.process(PublishItem{0, h});

  drain(lcm);
  const dynavins_lcm::path_t& got_path = rx.path;
  const dynavins_lcm::loop_hypotheses_t& got_h = rx.hypotheses;
  CHECK(rx.count["PC"] == 1);
  CHECK(got_path.num_poses == 3);
  REQUIRE(got_h.num_hypotheses == 2);
  CHECK(got_h.group_first_utime == 1'000'000);
  CHECK(got_h.group_size == 9);
  CHECK(got_h.hypotheses[0].weight == 0.97f);
  CHECK(got_h.hypotheses[0].num_loops == 2);
  CHECK(got_h.hypotheses[0].match_utime[1] == 150'000);
  CHECK(got_h.hypotheses[1].num_loops == 1);
  const PublisherStats st = pub.stats();
  CHECK(st.corrected_poses == 1);
  CHECK(st.paths == 1);
  CHECK(st.hypotheses == 1);
}
