// MipTexture: pyramid construction and footprint-filtered sampling.

#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/core.hpp>

#include "sim/render/mip_texture.hpp"

using namespace dynavins::sim;

TEST_CASE("MipTexture: levels halve down to 1x1 and keep the mean", "[texture][mip]") {
  cv::Mat img(300, 517, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  const MipTexture tex(img);
  CHECK(tex.width() == 517);
  CHECK(tex.height() == 300);
  CHECK(tex.num_levels() == 11);  // 517 -> 259 -> 130 -> 65 -> 33 -> 17 -> 9 -> 5 -> 3 -> 2 -> 1
  const double mean0 = cv::mean(img)[0];
  for (int k = 1; k < tex.num_levels(); ++k) {
    CHECK(tex.level_mat(k).cols == (tex.level_mat(k - 1).cols + 1) / 2);
    CHECK(std::abs(cv::mean(tex.level_mat(k))[0] - mean0) < 2.0);
  }
  CHECK(tex.bytes() > img.total());
  CHECK(tex.bytes() < img.total() * 3 / 2);
}

TEST_CASE("MipTexture: bilinear sampling hits texel values at texel centres", "[texture][mip]") {
  cv::Mat img = (cv::Mat_<uint8_t>(2, 4) << 0, 40, 80, 120, 200, 210, 220, 230);
  const MipTexture tex(img);
  // Texel (c, r) centre is at s = (c + 0.5) / w, r = (r + 0.5) / h.
  CHECK(tex.bilinear(0, 1.5f / 4, 0.25f) == Approx(40.0f));
  CHECK(tex.bilinear(0, 3.5f / 4, 0.75f) == Approx(230.0f));
  CHECK(tex.bilinear(0, 2.0f / 4, 0.25f) == Approx(60.0f));  // halfway between 40 and 80
  CHECK(tex.bilinear(0, 1.5f / 4, 0.5f) == Approx(125.0f));  // halfway between rows
}

TEST_CASE("MipTexture: a constant texture samples to the constant at any footprint", "[texture][mip]") {
  const MipTexture tex(cv::Mat(64, 128, CV_8UC1, cv::Scalar(77)));
  for (float f : {0.001f, 0.01f, 0.1f, 1.0f}) {
    CHECK(tex.sample(0.3f, 0.6f, f, 0.0f, 0.0f, f * 0.1f, 8) == Approx(77.0f).margin(1e-3));
    CHECK(tex.sample(0.99f, 0.01f, f, f, -f, f, 8) == Approx(77.0f).margin(1e-3));
  }
}

TEST_CASE("MipTexture: minified fine detail averages instead of aliasing", "[texture][mip]") {
  // One-texel checkerboard: point sampling at any texel centre returns 0 or 255.
  cv::Mat img(256, 256, CV_8UC1);
  for (int r = 0; r < 256; ++r)
    for (int c = 0; c < 256; ++c) img.at<uint8_t>(r, c) = ((r + c) % 2) ? 255 : 0;
  const MipTexture tex(img);
  const float step = 4.0f / 256.0f;  // one pixel covers 4x4 texels
  double worst = 0.0;
  for (int k = 0; k < 50; ++k) {
    const float s = 0.1f + 0.0137f * k, r = 0.2f + 0.0111f * k;
    worst = std::max(worst, std::abs(tex.sample(s, r, step, 0.0f, 0.0f, step, 8) - 127.5));
  }
  INFO("largest deviation from the mean " << worst);
  CHECK(worst < 3.0);
}

TEST_CASE("MipTexture: anisotropic footprints blur only along their long axis", "[texture][mip]") {
  // Columns ramp slowly along s; rows alternate 0 / +100 along r (detail the footprint must average).
  cv::Mat img(512, 512, CV_8UC1);
  for (int r = 0; r < 512; ++r)
    for (int c = 0; c < 512; ++c) img.at<uint8_t>(r, c) = static_cast<uint8_t>(c / 8 + (r % 2 ? 100 : 0));
  const MipTexture tex(img);
  // Pixel steps: 1 texel along s per u, 16 texels along r per v (a surface seen at a grazing angle).
  const float ds = 1.0f / 512, dr = 16.0f / 512;
  for (int c : {100, 220, 340}) {
    const float s = (c + 0.5f) / 512;
    const float got = tex.sample(s, 0.5f, ds, 0.0f, 0.0f, dr, 16);
    CHECK(got == Approx(c / 8.0 + 50.0).margin(2.0));  // rows averaged, column ramp kept
  }
  // Isotropic filtering of the same footprint would blur the ramp over 16 texels; the probe along the
  // short axis keeps neighbouring columns 8 texels apart distinct by the ramp's 1 level.
  const float a = tex.sample((200 + 0.5f) / 512, 0.5f, ds, 0.0f, 0.0f, dr, 16);
  const float b = tex.sample((264 + 0.5f) / 512, 0.5f, ds, 0.0f, 0.0f, dr, 16);
  CHECK(b - a == Approx(8.0f).margin(1.0));
}
