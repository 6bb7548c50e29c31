// feature_overlay: reading features.csv (with errors naming line and field), picking frames,
// and the drawing itself (green circles where weight >= 0.5, red crosses below, caption band).
#include "eval/feature_overlay.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace dynavins::eval;
namespace fs = std::filesystem;

namespace {

bool is_colour(const cv::Vec3b& c, const cv::Scalar& want, int tol = 60) {
  for (int k = 0; k < 3; ++k) {
    if (std::abs(static_cast<int>(c[k]) - static_cast<int>(want[k])) > tol) return false;
  }
  return true;
}

// Pixels of `want` colour inside a square of half size `h` around (x, y).
int count_near(const cv::Mat& img, int x, int y, int h, const cv::Scalar& want) {
  int n = 0;
  for (int yy = y - h; yy <= y + h; ++yy) {
    for (int xx = x - h; xx <= x + h; ++xx) {
      if (xx >= 0 && yy >= 0 && xx < img.cols && yy < img.rows && is_colour(img.at<cv::Vec3b>(yy, xx), want)) ++n;
    }
  }
  return n;
}

fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("dynavins_test_overlay_" + name);
  std::ofstream(p) << text;
  return p;
}

const char* kHeader = "t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z\n";

}  // namespace

TEST_CASE("draw_feature_overlay: green circle for kept, red cross for rejected", "[eval][overlay]") {
  const cv::Mat gray(120, 200, CV_8UC1, cv::Scalar(128));
  const std::vector<OverlayFeature> f = {{50, 60, 0.9, 0}, {150, 60, 0.1, 1}, {-5, 10, 1.0, 0}, {400, 10, 0.0, 0}};
  OverlayStyle style;
  style.caption = false;
  const cv::Mat out = draw_feature_overlay(gray, f, {}, style);
  REQUIRE(out.type() == CV_8UC3);
  REQUIRE(out.size() == gray.size());
  // Circle: its ring is green, its centre still the gray image; no red near it.
  CHECK(count_near(out, 50, 60, 7, kKeptColor) > 10);
  CHECK(count_near(out, 50, 60, 7, kRejectedColor) == 0);
  CHECK(is_colour(out.at<cv::Vec3b>(60, 50), cv::Scalar(128, 128, 128), 5));
  // Cross: red on its centre and diagonals, no green.
  CHECK(is_colour(out.at<cv::Vec3b>(60, 150), kRejectedColor));
  CHECK(is_colour(out.at<cv::Vec3b>(57, 147), kRejectedColor));
  CHECK(count_near(out, 150, 60, 7, kKeptColor) == 0);
  // Far from both features the image is untouched.
  CHECK(is_colour(out.at<cv::Vec3b>(100, 100), cv::Scalar(128, 128, 128), 0));
  // The input stays as it was.
  CHECK(cv::countNonZero(gray != 128) == 0);
}

TEST_CASE("draw_feature_overlay: caption band and bad images", "[eval][overlay]") {
  const cv::Mat bgr(100, 300, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Mat out = draw_feature_overlay(bgr, {}, "t 1.00 s | 0 features");
  CHECK(out.rows > bgr.rows);
  CHECK(out.cols == bgr.cols);
  CHECK(cv::countNonZero(out(cv::Rect(0, bgr.rows, bgr.cols, out.rows - bgr.rows)).reshape(1) > 200) > 0);  // text
  CHECK_THROWS_AS(draw_feature_overlay(cv::Mat(), {}), std::invalid_argument);
  CHECK_THROWS_AS(draw_feature_overlay(cv::Mat(10, 10, CV_32FC1), {}), std::invalid_argument);
}

TEST_CASE("read_feature_frames groups rows by time and names bad fields", "[eval][overlay]") {
  const fs::path ok = write_file("ok.csv", std::string(kHeader) +
                                               "100,1,7,10.5,20.25,0.9,3,0,1,2,3\n"
                                               "100,1,8,30,40,0.2,3,2,1,2,3\n"
                                               "200,2,7,11,21,0.8,4,-1,1,2,3\n");
  const auto frames = read_feature_frames(ok.string());
  REQUIRE(frames.size() == 2);
  CHECK(frames[0].t_ns == 100);
  REQUIRE(frames[0].features.size() == 2);
  CHECK(frames[0].features[0].u == Approx(10.5));
  CHECK(frames[0].features[0].v == Approx(20.25));
  CHECK(frames[0].rejected() == 1);
  CHECK(frames[0].moving() == 1);
  CHECK(frames[1].features[0].sim_label == -1);

  const fs::path bad = write_file("bad.csv", std::string(kHeader) + "100,1,7,10,20,0.9,3,0,1,2,3\n100,1,8,abc,40,0.2,3,2,1,2,3\n");
  try {
    read_feature_frames(bad.string());
    FAIL("no error");
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    CHECK(msg.find(bad.string() + ":3") != std::string::npos);
    CHECK(msg.find("'u'") != std::string::npos);
  }
  const fs::path no_col = write_file("nocol.csv", "t_ns,seq,u,v\n1,1,2,3\n");
  CHECK_THROWS_WITH(read_feature_frames(no_col.string()), Catch::Contains("weight"));
  const fs::path short_row = write_file("short.csv", std::string(kHeader) + "100,1,7\n");
  CHECK_THROWS_WITH(read_feature_frames(short_row.string()), Catch::Contains(":2"));
  CHECK_THROWS_WITH(read_feature_frames("/nonexistent/features.csv"), Catch::Contains("/nonexistent/features.csv"));
}

TEST_CASE("pick_overlay_frames prefers moving, then rejected, keeps a time gap", "[eval][overlay]") {
  auto frame = [](std::int64_t t_s, int moving, int rejected, int kept) {
    FeatureFrame f;
    f.t_ns = t_s * 1'000'000'000;
    for (int i = 0; i < moving; ++i) f.features.push_back({1, 1, 0.1, 1});
    for (int i = 0; i < rejected; ++i) f.features.push_back({1, 1, 0.1, 0});
    for (int i = 0; i < kept; ++i) f.features.push_back({1, 1, 0.9, 0});
    return f;
  };
  const std::vector<FeatureFrame> frames = {frame(0, 0, 9, 5), frame(10, 5, 0, 5), frame(11, 4, 0, 5),
                                            frame(20, 3, 0, 5), frame(30, 0, 2, 5)};
  CHECK(pick_overlay_frames(frames, 1) == std::vector<std::size_t>{1});
  // 11 s is within 2 s of 10 s: skipped; then 20 s (3 moving), then 0 s (most rejected): time order.
  CHECK(pick_overlay_frames(frames, 3) == std::vector<std::size_t>{0, 1, 3});
  CHECK(pick_overlay_frames(frames, 10).size() == 4);
  CHECK(pick_overlay_frames({}, 3).empty());
}

TEST_CASE("overlay_caption and tile_images", "[eval][overlay]") {
  FeatureFrame f;
  f.features = {{1, 1, 0.9, 0}, {1, 1, 0.1, 1}, {1, 1, 0.2, 0}, {1, 1, 0.8, 2}};
  const std::string c = overlay_caption(f, 12.345);
  CHECK(c.find("t 12.35 s") != std::string::npos);
  CHECK(c.find("4 features, 2 rejected (50 %)") != std::string::npos);
  CHECK(c.find("2 on moving objects, 1 of them rejected") != std::string::npos);

  const cv::Mat a(10, 20, CV_8UC3, cv::Scalar(255, 0, 0)), b(10, 20, CV_8UC3, cv::Scalar(0, 255, 0));
  const cv::Mat t = tile_images({a, b, a}, 2);
  REQUIRE(t.size() == cv::Size(40, 20));
  CHECK(t.at<cv::Vec3b>(5, 5) == cv::Vec3b(255, 0, 0));
  CHECK(t.at<cv::Vec3b>(5, 25) == cv::Vec3b(0, 255, 0));
  CHECK(t.at<cv::Vec3b>(15, 5) == cv::Vec3b(255, 0, 0));
  CHECK(t.at<cv::Vec3b>(15, 25) == cv::Vec3b(0, 0, 0));
  CHECK_THROWS_AS(tile_images({a, cv::Mat(5, 5, CV_8UC3)}, 2), std::invalid_argument);
  CHECK_THROWS_AS(tile_images({}, 2), std::invalid_argument);
}
