// The tracker copies the simulator's label under each feature (scoring only), and leaves -1 without labels.
#include <catch2/catch.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/common/estimator_options.hpp"
#include "stages/tracker/stereo_tracker.hpp"

using namespace dynavins;

TEST_CASE("tracker::StereoTracker fills sim_label from the label image at the rounded left pixel", "[vio][tracker]") {
  const auto o = EstimatorOptions::load(std::string(DYNAVINS_SHARED_DIR) +
                                        "/data/vins_fusion_euroc_config/euroc_stereo_imu_config.yaml");
  tracker::StereoTracker tracker(tracker::TrackerOptions::from(o), o.cameras[0]);
  cv::Mat img(o.image_height, o.image_width, CV_8U);
  cv::RNG rng(7);
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(img, img, cv::Size(5, 5), 1.5);
  StereoFrame f;
  f.t_ns = 1'000'000'000;
  f.left = img;
  f.labels = cv::Mat(img.size(), CV_8U, cv::Scalar(0));
  f.labels.colRange(img.cols / 2, img.cols).setTo(3);  // right half: moving object 3

  const TrackedFrame out = tracker.process(f);
  REQUIRE(out.features.size() > 20);
  int left = 0, right = 0;
  for (const TrackedFeature& t : out.features) {
    const int c = static_cast<int>(std::lround(t.px.x()));
    CHECK(t.sim_label == (c >= img.cols / 2 ? 3 : 0));
    (c >= img.cols / 2 ? right : left)++;
  }
  CHECK(left > 5);
  CHECK(right > 5);

  f.t_ns += 50'000'000;
  f.labels = cv::Mat();
  for (const TrackedFeature& t : tracker.process(f).features) CHECK(t.sim_label == -1);

  f.t_ns += 50'000'000;
  f.labels = cv::Mat(10, 10, CV_8U, cv::Scalar(0));
  CHECK_THROWS_AS(tracker.process(f), std::invalid_argument);
}
