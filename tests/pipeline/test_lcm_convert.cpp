// Every wire type: in-process message -> LCM encode -> publish on memq:// -> decode -> message.
#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>

#include "pipeline/lcm_channels.hpp"
#include "pipeline/lcm_convert.hpp"
#include "pipeline/pipeline.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

template <typename Msg>
struct Receiver {
  Msg received;
  std::string channel;
  int count = 0;
  void on_message(const lcm::ReceiveBuffer*, const std::string& ch, const Msg* m) {
    received = *m;
    channel = ch;
    ++count;
  }
};

/// Publishes `msg` on an in-process LCM and returns what a subscriber decoded.
template <typename Msg>
Msg through_memq(const Msg& msg, const std::string& channel) {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  Receiver<Msg> rx;
  lcm.subscribe(channel, &Receiver<Msg>::on_message, &rx);
  REQUIRE(lcm.publish(channel, &msg) == 0);
  REQUIRE(lcm.handleTimeout(1000) > 0);
  REQUIRE(rx.count == 1);
  CHECK(rx.channel == channel);
  return rx.received;
}

cv::Mat test_image(int seed) {
  cv::Mat img(48, 64, CV_8UC1);
  cv::randu(img, seed, 255);
  return img;
}

}  // namespace

TEST_CASE("stereo_image_t round trip, raw gray8 and PNG", "[lcm]") {
  StereoFrame f;
  f.t_ns = 1403715273262142976;
  f.seq = 42;
  f.left = test_image(0);
  f.right = test_image(7);
  for (auto enc : {ImageEncoding::Gray8, ImageEncoding::Png}) {
    const StereoFrame g = from_lcm(through_memq(to_lcm(f, enc), channels::kStereo));
    CHECK(g.t_ns == 1403715273262143000);  // microseconds on the wire
    CHECK(g.seq == 42);
    CHECK(cv::norm(g.left, f.left, cv::NORM_INF) == 0);
    CHECK(cv::norm(g.right, f.right, cv::NORM_INF) == 0);
  }
  f.right = cv::Mat();  // mono
  CHECK(from_lcm(through_memq(to_lcm(f, ImageEncoding::Png), channels::kStereo)).right.empty());
}

TEST_CASE("image_t with inconsistent data is rejected with the field named", "[lcm]") {
  auto msg = image_to_lcm(test_image(1), 0, ImageEncoding::Gray8);
  msg.width = 10;
  CHECK_THROWS_WITH(image_from_lcm(msg), Catch::Contains("gray8 data"));
  msg.width = -64, msg.height = -48;  // test_image is 64 x 48: the product of the negated sizes still matches
  CHECK_THROWS_WITH(image_from_lcm(msg), Catch::Contains("gray8 data"));
  auto png = image_to_lcm(test_image(1), 0, ImageEncoding::Png);
  png.data[20] ^= 0xff;
  png.data.resize(40);
  png.size = 40;
  CHECK_THROWS(image_from_lcm(png));
  msg = image_to_lcm(test_image(1), 0, ImageEncoding::Gray8);
  msg.encoding = 9;
  CHECK_THROWS_WITH(image_from_lcm(msg), Catch::Contains("encoding"));
}

TEST_CASE("imu_t round trip", "[lcm]") {
  ImuSample s;
  s.t_ns = 123456789000;
  s.acc = {0.1, -0.2, 9.81};
  s.gyr = {0.01, 0.02, -0.03};
  const ImuSample r = from_lcm(through_memq(to_lcm(s), channels::kImu));
  CHECK(r.t_ns == s.t_ns);
  CHECK(r.acc == s.acc);
  CHECK(r.gyr == s.gyr);
}

TEST_CASE("ground_truth_t round trip", "[lcm]") {
  GroundTruthState gt;
  gt.t_ns = 5000000;
  gt.p_wb = {1, 2, 3};
  gt.q_wb = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  gt.v_wb = {0.5, 0.6, 0.7};
  gt.bias_gyr = {1e-3, 2e-3, 3e-3};
  gt.bias_acc = {0.1, 0.2, 0.3};
  gt.has_velocity = gt.has_biases = true;
  const GroundTruthState r = from_lcm(through_memq(to_lcm(gt), channels::kGroundTruth));
  CHECK(r.t_ns == gt.t_ns);
  CHECK(r.p_wb == gt.p_wb);
  CHECK(r.q_wb.coeffs().isApprox(gt.q_wb.coeffs(), 1e-15));
  CHECK(r.v_wb == gt.v_wb);
  CHECK(r.bias_gyr == gt.bias_gyr);
  CHECK(r.bias_acc == gt.bias_acc);
  CHECK(r.has_velocity);
  CHECK(r.has_biases);
}

TEST_CASE("pose_t round trip and bad source / quaternion rejected", "[lcm]") {
  PoseEstimate p;
  p.source = PoseSource::LoopCorrected;
  p.state.t_ns = 7000;
  p.state.p_wb = {4, 5, 6};
  p.state.q_wb = Eigen::Quaterniond(0, 1, 0, 0);
  p.state.v_wb = {1, 0, 0};
  const PoseEstimate r = from_lcm(through_memq(to_lcm(p), channels::kPose));
  CHECK(r.source == PoseSource::LoopCorrected);
  CHECK(r.state.t_ns == 7000);
  CHECK(r.state.p_wb == p.state.p_wb);
  CHECK(r.state.q_wb.coeffs() == p.state.q_wb.coeffs());
  auto bad = to_lcm(p);
  bad.source = 7;
  CHECK_THROWS_WITH(from_lcm(bad), Catch::Contains("pose_t.source"));
  bad = to_lcm(p);
  bad.orientation[1] = 0;
  CHECK_THROWS_WITH(from_lcm(bad), Catch::Contains("orientation"));
}

TEST_CASE("weighted_feature_set_t round trip", "[lcm]") {
  WeightedFeatureSet set;
  set.t_ns = 9000;
  for (int i = 0; i < 5; ++i) {
    WeightedFeature f;
    f.id = 100 + i;
    f.u = 10.5f * i;
    f.v = 3.25f * i;
    f.p_w = {1.0 * i, 2.0, 3.0};
    f.weight = 0.2f * i;
    f.times_solved = i;
    f.sim_label = static_cast<int8_t>(i % 2);
    set.features.push_back(f);
  }
  const WeightedFeatureSet r = from_lcm(through_memq(to_lcm(set), channels::kFeatures));
  REQUIRE(r.features.size() == 5);
  for (int i = 0; i < 5; ++i) {
    CHECK(r.features[i].id == set.features[i].id);
    CHECK(r.features[i].u == set.features[i].u);
    CHECK(r.features[i].v == set.features[i].v);
    CHECK(r.features[i].p_w == set.features[i].p_w);
    CHECK(r.features[i].weight == set.features[i].weight);
    CHECK(r.features[i].times_solved == set.features[i].times_solved);
    CHECK(r.features[i].sim_label == set.features[i].sim_label);
  }
}

TEST_CASE("loop_hypotheses_t round trip", "[lcm]") {
  dynavins_lcm::loop_hypotheses_t msg;
  msg.utime = 1;
  msg.group_first_utime = 2;
  msg.group_size = 12;
  for (int h = 0; h < 2; ++h) {
    dynavins_lcm::loop_hypothesis_t hyp{};
    hyp.weight = h ? 0.1f : 0.9f;
    hyp.position[0] = h;
    hyp.orientation[0] = 1;
    hyp.num_loops = 3;
    hyp.query_utime = {10, 11, 12};
    hyp.match_utime = {1, 2, 3};
    msg.hypotheses.push_back(hyp);
  }
  msg.num_hypotheses = 2;
  const auto r = through_memq(msg, channels::kLoops);
  REQUIRE(r.num_hypotheses == 2);
  CHECK(r.group_size == 12);
  CHECK(r.hypotheses[0].weight == 0.9f);
  CHECK(r.hypotheses[1].position[0] == 1);
  CHECK(r.hypotheses[1].match_utime == std::vector<int64_t>{1, 2, 3});
}

TEST_CASE("path_t round trip", "[lcm]") {
  dynavins_lcm::path_t msg;
  msg.utime = 77;
  for (int i = 0; i < 4; ++i) {
    PoseEstimate p;
    p.source = PoseSource::LoopCorrected;
    p.state.t_ns = i * 1000;
    p.state.p_wb = {double(i), 0, 0};
    msg.poses.push_back(to_lcm(p));
  }
  msg.num_poses = 4;
  const auto r = through_memq(msg, channels::kPath);
  REQUIRE(r.num_poses == 4);
  CHECK(from_lcm(r.poses[3]).state.p_wb.x() == 3);
}

TEST_CASE("pipeline_stats_t round trip", "[lcm]") {
  RunReport report;
  report.wall_s = 2.0;
  StageStats s;
  s.name = "tracker";
  s.processed = 40;
  s.process.mean_ms = 6.5;
  s.process.p95_ms = 7.5;
  report.stages.push_back(s);
  QueueStats q;
  q.name = "frames";
  q.capacity = 4;
  q.pushed = 41;
  q.delivered = 40;
  q.dropped = 1;
  report.queues.push_back(q);
  const auto r = through_memq(to_lcm(report, 123, 4.0), channels::kStats);
  CHECK(r.realtime_factor == 2.0);
  REQUIRE(r.num_stages == 1);
  CHECK(r.stages[0].name == "tracker");
  CHECK(r.stages[0].process_ms_p95 == 7.5f);
  REQUIRE(r.num_queues == 1);
  CHECK(r.queues[0].dropped == 1);
}
