// LoopVerifier on a synthetic revisit with known truth: 3-D points seen by two cameras, fabricated
// descriptors (the database entries are built directly, no images), then the recovered T_m^k against the
// true relative body pose; wrong correspondences are rejected; too few inliers or an implausible pose give
// no loop. Also the descriptor matcher's ratio test and uniqueness.
#include <cmath>
#include <random>

#include <catch2/catch.hpp>

#include "stages/loop/place/descriptor_matching.hpp"
#include "stages/loop/place/loop_verifier.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {

Eigen::Quaterniond rot(double deg, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()));
}

void random_descriptor(std::mt19937& rng, uint8_t* d) {
  std::uniform_int_distribution<int> byte(0, 255);
  for (int i = 0; i < 32; ++i) d[i] = static_cast<uint8_t>(byte(rng));
}

struct Scene {
  KeyframeDescriptors match, query;
  Eigen::Vector3d p_mq_true;
  Eigen::Quaterniond q_mq_true;
  int correct = 0;  // correspondences with the right query position
};

/// `shared` points seen by both keyframes (round(wrong * shared) of them, evenly spread, at a random query position,
/// i.e. wrong correspondences), plus `extra` unrelated points in each; pixel noise `noise_px` at 460 px focal.
Scene make_scene(int shared, double wrong, int extra, double noise_px, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(2.0, 8.0);
  std::normal_distribution<double> noise(0.0, noise_px / 460.0);
  Scene s;
  // EuRoC-like rig: camera looking along the body's x axis, small lever arm; the two keyframes have
  // slightly different extrinsics (as an online calibration would leave them).
  const Eigen::Quaterniond q_bc = rot(-90, Eigen::Vector3d::UnitZ()) * rot(-90, Eigen::Vector3d::UnitX());
  s.match.p_bc = Eigen::Vector3d(0.05, -0.02, 0.01);
  s.match.q_bc = q_bc;
  s.query.p_bc = Eigen::Vector3d(0.052, -0.021, 0.008);
  s.query.q_bc = q_bc * rot(0.3, Eigen::Vector3d(1, 1, 0));
  s.match.t_ns = 1'000'000'000;
  s.query.t_ns = 90'000'000'000;
  s.match.p_wb = Eigen::Vector3d(1.0, 2.0, 0.5);
  s.match.q_wb = rot(30, Eigen::Vector3d(0.1, 0.2, 1.0));
  s.p_mq_true = Eigen::Vector3d(0.4, -0.25, 0.1);
  s.q_mq_true = rot(12, Eigen::Vector3d(0.2, -0.1, 1.0));
  // The query's odometry pose has drifted: the verifier must not use it.
  s.query.p_wb = s.match.p_wb + s.match.q_wb * s.p_mq_true + Eigen::Vector3d(0.7, -0.4, 0.2);
  s.query.q_wb = s.match.q_wb * s.q_mq_true * rot(5, Eigen::Vector3d::UnitZ());
  // True query camera in the match camera frame: T_cm_ck = T_bc(m)^-1 * T_mq * T_bc(k).
  const Eigen::Quaterniond q_mb_kc = s.q_mq_true * s.query.q_bc;
  const Eigen::Vector3d p_mb_kc = s.p_mq_true + s.q_mq_true * s.query.p_bc;
  const Eigen::Quaterniond q_mc_kc = s.match.q_bc.conjugate() * q_mb_kc;
  const Eigen::Vector3d p_mc_kc = s.match.q_bc.conjugate() * (p_mb_kc - s.match.p_bc);
  const Eigen::Quaterniond q_wc = s.match.q_wb * s.match.q_bc;
  const Eigen::Vector3d p_wc = s.match.p_wb + s.match.q_wb * s.match.p_bc;

  s.match.descriptors = cv::Mat(0, 32, CV_8UC1);
  s.query.descriptors = cv::Mat(0, 32, CV_8UC1);
  std::uniform_int_distribution<int> bit(0, 255);
  int made = 0;
  while (made < shared) {
    const double z = depth(rng);
    const Eigen::Vector3d p_mc(u(rng) * 0.6 * z, u(rng) * 0.45 * z, z);
    const Eigen::Vector3d p_kc = q_mc_kc.conjugate() * (p_mc - p_mc_kc);
    if (p_kc.z() < 0.5 || std::abs(p_kc.x() / p_kc.z()) > 0.7 || std::abs(p_kc.y() / p_kc.z()) > 0.5) continue;
    KeyframePoint pm;
    pm.id = made;
    pm.has_p_w = true;
    pm.p_w = q_wc * p_mc + p_wc;
    pm.xy = p_mc.head<2>() / p_mc.z();
    KeyframePoint pk;
    pk.id = 10'000 + made;
    const bool is_wrong = std::floor((made + 1) * wrong) > std::floor(made * wrong);  // evenly spread, exact count
    pk.xy = is_wrong ? Eigen::Vector2d(u(rng) * 0.7, u(rng) * 0.5)
                     : Eigen::Vector2d(p_kc.head<2>() / p_kc.z() + Eigen::Vector2d(noise(rng), noise(rng)));
    if (!is_wrong) ++s.correct;
    cv::Mat dm(1, 32, CV_8UC1);
    random_descriptor(rng, dm.ptr<uint8_t>(0));
    cv::Mat dk = dm.clone();
    for (int f = 0; f < 6; ++f) {  // the query sees it a few bits differently
      const int b = bit(rng);
      dk.at<uint8_t>(0, b / 8) ^= static_cast<uint8_t>(1u << (b % 8));
    }
    s.match.points.push_back(pm);
    s.query.points.push_back(pk);
    s.match.descriptors.push_back(dm);
    s.query.descriptors.push_back(dk);
    ++made;
  }
  for (int e = 0; e < extra; ++e) {  // unrelated points in each keyframe
    for (KeyframeDescriptors* kd : {&s.match, &s.query}) {
      KeyframePoint p;
      p.xy = Eigen::Vector2d(u(rng) * 0.7, u(rng) * 0.5);
      p.has_p_w = kd == &s.match && e % 2 == 0;
      p.p_w = p_wc + q_wc * Eigen::Vector3d(u(rng), u(rng), depth(rng));
      cv::Mat d(1, 32, CV_8UC1);
      random_descriptor(rng, d.ptr<uint8_t>(0));
      kd->points.push_back(p);
      kd->descriptors.push_back(d);
    }
  }
  return s;
}

double angle_deg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a.conjugate() * b).angle() * 180.0 / M_PI;
}

}  // namespace

TEST_CASE("loop verifier: recovers T_m^k of a clean revisit") {
  const Scene s = make_scene(150, 0.0, 100, 0.3, 1);
  const LoopVerification v = LoopVerifier().verify(s.query, s.match);
  INFO(to_string(v.rejection) << ", matches " << v.matches << ", inliers " << v.inliers);
  REQUIRE(v.accepted);
  CHECK(v.matches == 150);
  CHECK(v.inliers >= 145);
  CHECK(v.loop.inliers == v.inliers);
  CHECK(v.loop.query_t_ns == s.query.t_ns);
  CHECK(v.loop.match_t_ns == s.match.t_ns);
  const double dp = (v.loop.p_mq - s.p_mq_true).norm(), dq = angle_deg(v.loop.q_mq, s.q_mq_true);
  INFO("translation error " << dp << " m, rotation error " << dq << " deg");
  CHECK(dp < 0.01);
  CHECK(dq < 0.5);
}

TEST_CASE("loop verifier: 30% wrong correspondences are rejected by RANSAC") {
  const Scene s = make_scene(150, 0.3, 100, 0.3, 2);
  const LoopVerification v = LoopVerifier().verify(s.query, s.match);
  INFO(to_string(v.rejection) << ", matches " << v.matches << ", inliers " << v.inliers << ", correct " << s.correct);
  REQUIRE(v.accepted);
  CHECK(v.matches == 150);
  CHECK(v.inliers >= s.correct - 5);
  CHECK(v.inliers <= s.correct + 3);  // a wrong one may land inside the 3 px threshold by chance
  const double dp = (v.loop.p_mq - s.p_mq_true).norm(), dq = angle_deg(v.loop.q_mq, s.q_mq_true);
  INFO("translation error " << dp << " m, rotation error " << dq << " deg");
  CHECK(dp < 0.01);
  CHECK(dq < 0.5);
}

TEST_CASE("loop verifier: too few inliers is no loop") {
  // 40 matches, 30 of them wrong: about 10 right ones, under the 15 DESIGN.md asks for.
  const Scene s = make_scene(40, 0.75, 50, 0.3, 3);
  REQUIRE(s.correct < 15);
  const LoopVerification v = LoopVerifier().verify(s.query, s.match);
  INFO(to_string(v.rejection) << ", matches " << v.matches << ", inliers " << v.inliers << ", correct " << s.correct);
  CHECK_FALSE(v.accepted);
  CHECK((v.rejection == LoopRejection::TooFewInliers || v.rejection == LoopRejection::PnpFailed));
  // Enough matches for PnP, but only the right ones (under 15) agree.
  const Scene some = make_scene(22, 0.4, 50, 0.3, 6);
  REQUIRE(some.correct < 15);
  const LoopVerification u = LoopVerifier().verify(some.query, some.match);
  INFO("second case: " << to_string(u.rejection) << ", matches " << u.matches << ", inliers " << u.inliers
                       << ", correct " << some.correct);
  CHECK_FALSE(u.accepted);
  CHECK(u.rejection == LoopRejection::TooFewInliers);
  CHECK(u.inliers >= some.correct - 2);
  // Too few matches at all.
  const Scene few = make_scene(10, 0.0, 50, 0.3, 4);
  const LoopVerification w = LoopVerifier().verify(few.query, few.match);
  CHECK_FALSE(w.accepted);
  CHECK(w.rejection == LoopRejection::TooFewMatches);
}

TEST_CASE("loop verifier: an implausible relative pose is no loop") {
  const Scene s = make_scene(100, 0.0, 0, 0.3, 5);
  LoopVerifierOptions opts;
  opts.max_translation_m = 0.3;  // the true |p_mq| is 0.48 m
  const LoopVerification v = LoopVerifier(opts).verify(s.query, s.match);
  CHECK_FALSE(v.accepted);
  CHECK(v.rejection == LoopRejection::Implausible);
  opts = {};
  opts.max_rotation_deg = 10;  // the true rotation is 12 deg
  CHECK(LoopVerifier(opts).verify(s.query, s.match).rejection == LoopRejection::Implausible);
}

TEST_CASE("descriptor matching: ratio test, distance cap, uniqueness, 3-D points only") {
  KeyframeDescriptors q, c;
  std::mt19937 rng(9);
  cv::Mat a(1, 32, CV_8UC1), b(1, 32, CV_8UC1);
  random_descriptor(rng, a.ptr<uint8_t>(0));
  random_descriptor(rng, b.ptr<uint8_t>(0));
  KeyframePoint with3d, without3d;
  with3d.has_p_w = true;
  // Candidate: a twice (ambiguous), b once with a 3-D point, b once more without one (ignored).
  c.points = {with3d, with3d, with3d, without3d};
  c.descriptors = cv::Mat(0, 32, CV_8UC1);
  c.descriptors.push_back(a);
  c.descriptors.push_back(a);
  c.descriptors.push_back(b);
  c.descriptors.push_back(b);
  // Query: a (ambiguous: ratio test drops it), b twice (one candidate point: one kept), NaN-xy b (skipped).
  KeyframePoint p, nan_xy;
  nan_xy.xy = Eigen::Vector2d(std::nan(""), 0);
  q.points = {p, p, p, nan_xy};
  q.descriptors = cv::Mat(0, 32, CV_8UC1);
  q.descriptors.push_back(a);
  q.descriptors.push_back(b);
  cv::Mat b1 = b.clone();
  b1.at<uint8_t>(0, 0) ^= 1;  // one bit further from b than query point 1
  q.descriptors.push_back(b1);
  q.descriptors.push_back(b);
  const auto m = match_descriptors(q, c);
  REQUIRE(m.size() == 1);
  CHECK(m[0].query == 1);
  CHECK(m[0].match == 2);
  CHECK(m[0].distance == 0);
  DescriptorMatchOptions strict;
  strict.max_hamming = -1;
  CHECK(match_descriptors(q, c, strict).empty());
}
