// compute_keyframe_descriptors on a real EuRoC image: tracked points keep their data and order, extra
// corners fill up to max_points, the border is respected, and the entry is a few tens of kilobytes.
#include <cmath>

#include <catch2/catch.hpp>

#include "stages/loop/place/keyframe_descriptors.hpp"
#include "tests/loop/place/euroc_images.hpp"

using namespace dynavins;
using namespace dynavins::loop;

TEST_CASE("keyframe descriptors: tracked points plus extra corners, no image kept") {
  Keyframe kf;
  kf.t_ns = 123;
  kf.seq = 7;
  kf.image = test::euroc_cam0_image(0);
  kf.p_bc = Eigen::Vector3d(0.1, 0.2, 0.3);
  // Three "tracked" points, one of them too close to the border.
  for (int i = 0; i < 3; ++i) {
    KeyframePoint p;
    p.id = 100 + i;
    p.px = i == 2 ? Eigen::Vector2d(5, 5) : Eigen::Vector2d(200 + 100 * i, 240);
    p.xy = Eigen::Vector2d(0.01 * i, 0.02);
    p.has_p_w = true;
    p.p_w = Eigen::Vector3d(i, 1, 2);
    kf.points.push_back(p);
  }
  DescriptorOptions opts;
  opts.max_points = 300;
  const KeyframeDescriptors d =
      compute_keyframe_descriptors(kf, opts, [](const Eigen::Vector2d& px) { return Eigen::Vector2d(px / 458.0); });
  REQUIRE(d.descriptors.type() == CV_8UC1);
  REQUIRE(d.descriptors.cols == 32);
  REQUIRE(d.descriptors.rows == static_cast<int>(d.points.size()));
  CHECK(d.points.size() > 250);  // a textured room: the extra corners fill up to the cap
  CHECK(d.points.size() <= 300);
  CHECK(d.t_ns == 123);
  CHECK(d.seq == 7);
  CHECK(d.p_bc.isApprox(kf.p_bc));
  // The two tracked points inside the border come first with their data; the border one is dropped.
  REQUIRE(d.points.size() >= 2);
  CHECK(d.points[0].id == 100);
  CHECK(d.points[1].id == 101);
  CHECK(d.points[1].p_w.isApprox(Eigen::Vector3d(1, 1, 2)));
  for (std::size_t i = 2; i < d.points.size(); ++i) {
    CHECK(d.points[i].id == -1);
    CHECK_FALSE(d.points[i].has_p_w);
    CHECK(d.points[i].px.x() >= opts.border_px);
    CHECK(d.points[i].px.y() < kf.image.rows - opts.border_px);
    CHECK(d.points[i].xy.isApprox(d.points[i].px / 458.0));
  }
}

TEST_CASE("keyframe descriptors: without an undistortion the extra corners have NaN xy") {
  Keyframe kf;
  kf.image = test::euroc_cam0_image(10);
  const KeyframeDescriptors d = compute_keyframe_descriptors(kf);
  REQUIRE(!d.points.empty());
  CHECK(std::isnan(d.points[0].xy.x()));
}

TEST_CASE("keyframe descriptors: the same image gives the same descriptors") {
  Keyframe kf;
  kf.image = test::euroc_cam0_image(20);
  const KeyframeDescriptors a = compute_keyframe_descriptors(kf), b = compute_keyframe_descriptors(kf);
  REQUIRE(a.descriptors.size() == b.descriptors.size());
  CHECK(cv::countNonZero(a.descriptors != b.descriptors) == 0);
}

TEST_CASE("keyframe descriptors: memory per keyframe under 64 kB for 500 points") {
  Keyframe kf;
  kf.image = test::euroc_cam0_image(30);
  DescriptorOptions opts;
  opts.max_points = 500;
  opts.corner_min_distance_px = 5;
  const KeyframeDescriptors d = compute_keyframe_descriptors(kf, opts);
  INFO("points " << d.points.size() << ", bytes " << d.memory_bytes());
  CHECK(d.points.size() > 400);
  CHECK(d.memory_bytes() < 64 * 1024);
  // Fabricated full entry of exactly 500 points.
  KeyframeDescriptors full;
  full.points.resize(500);
  full.descriptors = cv::Mat(500, 32, CV_8UC1, cv::Scalar(0));
  INFO("500 points: " << full.memory_bytes() << " bytes");
  CHECK(full.memory_bytes() < 64 * 1024);
}
