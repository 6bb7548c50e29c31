// pipeline/wire_decode: every type with a variable-length field round-trips through decode_payload
// (so the layout walk matches lcm-gen's encoding of lcm_types/), and a corrupt length field is
// rejected by name before anything is allocated (lcm-gen's decode would zero-fill 2 GB or throw
// std::length_error, see the header).
#include <catch2/catch.hpp>

#include <opencv2/core.hpp>

#include <dynavins_lcm/loop_hypotheses_t.hpp>
#include <dynavins_lcm/path_t.hpp>
#include <dynavins_lcm/pipeline_stats_t.hpp>
#include <dynavins_lcm/status_t.hpp>

#include "pipeline/lcm_convert.hpp"
#include "pipeline/wire_decode.hpp"

using namespace dynavins;
using namespace dynavins::pipeline;

namespace {

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  REQUIRE(m.encode(b.data(), 0, static_cast<int>(b.size())) == static_cast<int>(b.size()));
  return b;
}

void put_i32(std::vector<uint8_t>& b, std::size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}

template <typename Msg>
std::string rejection(const std::vector<uint8_t>& payload) {
  try {
    (void)decode_payload<Msg>(payload, "log.lcm: event #3");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

StereoFrame small_frame() {
  StereoFrame f;
  f.t_ns = 1'000'000'000;
  f.left = cv::Mat(4, 6, CV_8UC1, cv::Scalar(7));
  f.right = cv::Mat(4, 6, CV_8UC1, cv::Scalar(9));
  return f;
}

// Byte offset of image_t.size in an encoded stereo_image_t: fingerprint, utime, seq, then the left
// image's utime, width, height, encoding.
constexpr std::size_t kLeftSizeAt = 8 + 8 + 8 + 8 + 4 + 4 + 1;

}  // namespace

TEST_CASE("wire_decode: every variable-length type round-trips") {
  const auto stereo = encode(to_lcm(small_frame(), ImageEncoding::Gray8));
  CHECK(wire_length_problem("stereo_image_t", stereo.data(), stereo.size()).empty());
  const auto back = from_lcm(decode_payload<dynavins_lcm::stereo_image_t>(stereo, "x"));
  CHECK(cv::countNonZero(back.right != 9) == 0);

  dynavins_lcm::weighted_feature_set_t features{};
  features.num_features = 3;
  features.features.resize(3);
  features.features[2].id = 42;
  CHECK(decode_payload<dynavins_lcm::weighted_feature_set_t>(encode(features), "x").features[2].id == 42);

  dynavins_lcm::path_t path{};
  path.num_poses = 2;
  path.poses.resize(2);
  path.poses[1].utime = 5;
  CHECK(decode_payload<dynavins_lcm::path_t>(encode(path), "x").poses[1].utime == 5);

  dynavins_lcm::loop_hypotheses_t hyp{};
  hyp.num_hypotheses = 2;
  hyp.hypotheses.resize(2);
  hyp.hypotheses[1].num_loops = 3;
  hyp.hypotheses[1].query_utime = {1, 2, 3};
  hyp.hypotheses[1].match_utime = {4, 5, 6};
  CHECK(decode_payload<dynavins_lcm::loop_hypotheses_t>(encode(hyp), "x").hypotheses[1].match_utime[2] == 6);

  dynavins_lcm::status_t status{};
  status.reason = "reset: imu gap";
  CHECK(decode_payload<dynavins_lcm::status_t>(encode(status), "x").reason == "reset: imu gap");

  dynavins_lcm::pipeline_stats_t stats{};
  stats.num_stages = 2;
  stats.stages.resize(2);
  stats.stages[1].name = "estimator";
  stats.num_queues = 1;
  stats.queues.resize(1);
  stats.queues[0].name = "frames";
  const auto s = decode_payload<dynavins_lcm::pipeline_stats_t>(encode(stats), "x");
  CHECK(s.stages[1].name == "estimator");
  CHECK(s.queues[0].name == "frames");
}

TEST_CASE("wire_decode: a corrupt length field is named, not allocated") {
  auto stereo = encode(to_lcm(small_frame(), ImageEncoding::Gray8));
  REQUIRE(stereo[kLeftSizeAt + 3] == 24);  // 6x4 gray8: the offset above is image_t.size

  SECTION("image_t.size of 2^31 - 1 (lcm-gen's decode would zero-fill 2 GB first)") {
    put_i32(stereo, kLeftSizeAt, 0x7fffffffu);
    const std::string what = rejection<dynavins_lcm::stereo_image_t>(stereo);
    CHECK_THAT(what, Catch::Contains("log.lcm: event #3: payload is not a valid stereo_image_t"));
    CHECK_THAT(what, Catch::Contains("image_t.size 2147483647 needs 2147483647 bytes"));
    CHECK_THAT(what, Catch::Contains("at byte " + std::to_string(kLeftSizeAt + 4)));
  }
  SECTION("a negative image_t.size (std::length_error from lcm-gen's decode)") {
    put_i32(stereo, kLeftSizeAt, 0xfffffff0u);
    CHECK_THAT(rejection<dynavins_lcm::stereo_image_t>(stereo), Catch::Contains("image_t.size is negative (-16)"));
  }
  SECTION("trailing bytes") {
    stereo.push_back(0);
    CHECK_THAT(rejection<dynavins_lcm::stereo_image_t>(stereo), Catch::Contains("1 bytes after the end"));
  }
  SECTION("another type's payload") {
    ImuSample imu;
    CHECK_THAT(rejection<dynavins_lcm::stereo_image_t>(encode(to_lcm(imu))), Catch::Contains("fingerprint is not"));
  }
  SECTION("a string length of 0 (std::string would be asked for SIZE_MAX bytes)") {
    dynavins_lcm::status_t status{};
    status.reason = "x";
    auto b = encode(status);
    put_i32(b, 8 + 8 + 1, 0);
    CHECK_THAT(rejection<dynavins_lcm::status_t>(b), Catch::Contains("status_t.reason has length 0"));
  }
  SECTION("a feature count far beyond the payload") {
    dynavins_lcm::weighted_feature_set_t features{};
    auto b = encode(features);
    put_i32(b, 8 + 8, 100'000'000u);
    CHECK_THAT(rejection<dynavins_lcm::weighted_feature_set_t>(b),
               Catch::Contains("weighted_feature_set_t.num_features 100000000 needs"));
  }
}
