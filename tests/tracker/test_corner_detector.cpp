// detect_corners against OpenCV's goodFeaturesToTrack (the same Shi-Tomasi algorithm over the whole
// image): the tiled response must find the same corners under any mask.
#include <algorithm>
#include <random>

#include <catch2/catch.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/tracker/corner_detector.hpp"

using namespace dynavins;
using namespace dynavins::tracker;

namespace {

cv::Mat textured_image(int seed) {
  cv::Mat img(480, 752, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 2.5);
  cv::normalize(img, img, 0, 255, cv::NORM_MINMAX);
  return img;
}

/// Free everywhere except discs around random "tracks", as the tracker's min-distance mask.
cv::Mat disc_mask(const cv::Size& size, int discs, int radius, int seed) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(0, size.width - 1), v(0, size.height - 1);
  for (int i = 0; i < discs; ++i) cv::circle(mask, cv::Point(u(rng), v(rng)), radius, cv::Scalar(0), cv::FILLED);
  return mask;
}

std::vector<std::pair<float, float>> sorted(const std::vector<cv::Point2f>& pts) {
  std::vector<std::pair<float, float>> s;
  for (const auto& p : pts) s.emplace_back(p.x, p.y);
  std::sort(s.begin(), s.end());
  return s;
}

}  // namespace

TEST_CASE("detect_corners finds goodFeaturesToTrack's corners under a tracker's mask") {
  for (int seed = 1; seed <= 3; ++seed) {
    const cv::Mat img = textured_image(seed);
    for (int discs : {0, 60, 140}) {
      const cv::Mat mask = disc_mask(img.size(), discs, 30, seed);
      const int wanted = 150 - discs / 2;
      std::vector<cv::Point2f> expected;
      cv::goodFeaturesToTrack(img, expected, wanted, 0.01, 30, mask, 3, false);
      const auto found = detect_corners(img, mask, wanted, 0.01, 30);
      INFO("seed " << seed << ", discs " << discs);
      REQUIRE(found.size() == expected.size());
      CHECK(sorted(found) == sorted(expected));
      for (const auto& p : found) CHECK(mask.at<uchar>(cvRound(p.y), cvRound(p.x)) != 0);
    }
  }
}

TEST_CASE("detect_corners returns nothing when the whole image is masked") {
  const cv::Mat img = textured_image(4);
  CHECK(detect_corners(img, cv::Mat::zeros(img.size(), CV_8UC1), 50, 0.01, 30).empty());
}
