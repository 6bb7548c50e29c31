// Photometric effects: determinism, noise level, gain drift, night mode, vignetting, no saturation.

#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/core.hpp>

#include "sim/render/photometric.hpp"

using namespace dynavins::sim;

TEST_CASE("Photometric: deterministic per seed, time and camera", "[render][photometric]") {
  const cv::Mat img(480, 752, CV_8UC1, cv::Scalar(120));
  PhotometricOptions o;
  o.seed = 4;
  const cv::Mat a = apply_photometric(img, o, 1.25, 0), b = apply_photometric(img, o, 1.25, 0);
  CHECK(cv::norm(a, b, cv::NORM_INF) == 0.0);
  CHECK(cv::norm(a, apply_photometric(img, o, 1.25, 1), cv::NORM_L1) > 0.0);  // right camera: other noise
  CHECK(cv::norm(a, apply_photometric(img, o, 1.30, 0), cv::NORM_L1) > 0.0);  // next frame: other noise
}

TEST_CASE("Photometric: noise sigma and mean follow the options", "[render][photometric]") {
  const cv::Mat img(480, 752, CV_8UC1, cv::Scalar(100));
  PhotometricOptions o;
  o.noise_sigma = 2.0;
  o.gain_drift = 0.0;
  o.gain = 1.1;
  o.offset = 3.0;
  cv::Scalar mean, sd;
  cv::meanStdDev(apply_photometric(img, o, 0.0), mean, sd);
  CHECK(mean[0] == Approx(113.0).margin(0.1));
  // Rounding to integers adds 1/12 of a level squared to the variance.
  CHECK(sd[0] == Approx(std::sqrt(4.0 + 1.0 / 12.0)).epsilon(0.03));
}

TEST_CASE("Photometric: the gain drifts slowly and within its amplitude", "[render][photometric]") {
  PhotometricOptions o;
  o.gain_drift = 0.1;
  double lo = 10, hi = 0, worst_step = 0;
  for (int k = 0; k <= 1200; ++k) {  // 60 s at 20 Hz
    const double g = photometric_gain(o, 0.05 * k);
    lo = std::min(lo, g);
    hi = std::max(hi, g);
    if (k > 0) worst_step = std::max(worst_step, std::abs(g - photometric_gain(o, 0.05 * (k - 1))));
  }
  CHECK(lo >= 0.9 - 1e-9);
  CHECK(hi <= 1.1 + 1e-9);
  CHECK(hi - lo > 0.1);            // it does vary over a minute
  CHECK(worst_step < 0.01);        // by less than 1% between frames
}

TEST_CASE("Photometric: night is darker and noisier, vignetting darkens the corners", "[render][photometric]") {
  const cv::Mat img(480, 752, CV_8UC1, cv::Scalar(150));
  const PhotometricOptions night = PhotometricOptions::night();
  const cv::Mat n = apply_photometric(img, night, 2.0);
  const cv::Mat d = apply_photometric(img, PhotometricOptions{}, 2.0);
  CHECK(cv::mean(n)[0] < 0.5 * cv::mean(d)[0]);
  const cv::Rect centre(326, 190, 100, 100);
  cv::Scalar m, sd_night, sd_day;
  cv::meanStdDev(n(centre), m, sd_night);
  cv::meanStdDev(d(centre), m, sd_day);
  CHECK(sd_night[0] > 1.5 * sd_day[0]);
  PhotometricOptions v;
  v.noise_sigma = 0.0;
  v.gain_drift = 0.0;
  v.vignetting = 0.3;
  const cv::Mat vig = apply_photometric(img, v, 0.0);
  CHECK(vig.at<uint8_t>(240, 376) == 150);
  CHECK(vig.at<uint8_t>(0, 0) == Approx(150 * 0.7).margin(1.0));
}
