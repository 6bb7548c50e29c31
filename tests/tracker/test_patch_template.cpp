// capture_patch / refine_patch: recovering a known affine warp with gain and offset, and the failures.
#include <cmath>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/tracker/patch_template.hpp"

using namespace dynavins;
using namespace dynavins::tracker;

namespace {

/// Smooth random texture (blurred noise), deterministic.
cv::Mat texture(int seed) {
  cv::Mat noise(240, 320, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);
  cv::Mat out;
  cv::normalize(noise, noise, 20, 235, cv::NORM_MINMAX);
  noise.convertTo(out, CV_8U);
  return out;
}

/// `img` seen through x_new = M x_old (2x3), with gain and offset on the intensities.
cv::Mat warped(const cv::Mat& img, const cv::Matx23d& M, double gain, double offset) {
  cv::Mat out;
  cv::warpAffine(img, out, M, img.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  out.convertTo(out, CV_8U, gain, offset);
  return out;
}

}  // namespace

TEST_CASE("refine_patch recovers an affine warp with a gain and an offset", "[tracker][patch]") {
  const cv::Mat a = texture(1);
  const Eigen::Vector2f p(160.3f, 119.6f);
  const auto tmpl = capture_patch(a, p);
  REQUIRE(tmpl);
  // 12 % bigger, turned 6 degrees, moved; 20 % brighter with an offset.
  const double s = 1.12, th = 6.0 * CV_PI / 180.0;
  Eigen::Matrix2d L;
  L << s * std::cos(th), -s * std::sin(th), s * std::sin(th), s * std::cos(th);
  const Eigen::Vector2d shift(4.0, -2.5);
  // x_new = L (x_old - p) + p + shift
  const Eigen::Vector2d c = p.cast<double>() + shift - L * p.cast<double>();
  const cv::Matx23d M(L(0, 0), L(0, 1), c.x(), L(1, 0), L(1, 1), c.y());
  const cv::Mat b = warped(a, M, 1.2, -15.0);
  const Eigen::Vector2f truth = (p.cast<double>() + shift).cast<float>();

  tracker::AffineWarp w;
  w.t = truth + Eigen::Vector2f(1.5f, -1.0f);  // a KLT answer off by 1.8 px, shape unknown
  const tracker::RefineOutcome o = refine_patch(*tmpl, b, &w, 20);
  REQUIRE(o.result == tracker::RefineResult::Converged);
  CHECK(o.ncc > 0.99f);
  CHECK((w.t - truth).norm() < 0.05f);
  CHECK((w.A.cast<double>() - L).norm() < 0.02);
  CHECK(w.scale() == Approx(s).epsilon(0.01));
}

TEST_CASE("refine_patch on the unchanged image stays put", "[tracker][patch]") {
  const cv::Mat a = texture(2);
  const Eigen::Vector2f p(100.7f, 80.2f);
  const auto tmpl = capture_patch(a, p);
  REQUIRE(tmpl);
  tracker::AffineWarp w;
  w.t = p + Eigen::Vector2f(0.6f, 0.4f);
  REQUIRE(refine_patch(*tmpl, a, &w).result == tracker::RefineResult::Converged);
  CHECK((w.t - p).norm() < 0.02f);
  CHECK((w.A - Eigen::Matrix2f::Identity()).norm() < 0.01f);
}

TEST_CASE("capture_patch refuses flat patches and the image border", "[tracker][patch]") {
  const cv::Mat flat(100, 100, CV_8U, cv::Scalar(128));
  CHECK_FALSE(capture_patch(flat, Eigen::Vector2f(50, 50)));
  const cv::Mat a = texture(3);
  CHECK_FALSE(capture_patch(a, Eigen::Vector2f(5, 50)));     // patch radius 7 + 1 rim
  CHECK_FALSE(capture_patch(a, Eigen::Vector2f(50, 232)));
  CHECK(capture_patch(a, Eigen::Vector2f(8.5f, 50)));
  cv::Mat rgb;
  cv::cvtColor(a, rgb, cv::COLOR_GRAY2BGR);
  CHECK_FALSE(capture_patch(rgb, Eigen::Vector2f(50, 50)));
}

TEST_CASE("refine_patch reports a patch that left the image or lost its texture", "[tracker][patch]") {
  const cv::Mat a = texture(4);
  const auto tmpl = capture_patch(a, Eigen::Vector2f(60, 60));
  REQUIRE(tmpl);
  tracker::AffineWarp w;
  w.t = Eigen::Vector2f(3, 60);
  CHECK(refine_patch(*tmpl, a, &w).result == tracker::RefineResult::OutOfImage);
  const cv::Mat flat(240, 320, CV_8U, cv::Scalar(90));
  w = tracker::AffineWarp{};
  w.t = Eigen::Vector2f(60, 60);
  CHECK(refine_patch(*tmpl, flat, &w).result == tracker::RefineResult::Diverged);
}

TEST_CASE("image_noise_sigma measures added noise on a textured image", "[tracker][patch]") {
  const cv::Mat a = texture(5);
  for (double sigma : {2.0, 5.0}) {
    cv::Mat f, noise(a.size(), CV_32F), noisy;
    a.convertTo(f, CV_32F);
    cv::RNG(6).fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    cv::Mat(f + noise).convertTo(noisy, CV_8U);
    // The texture leaks a little into the estimate and 8-bit rounding adds ~0.3 gray levels.
    CHECK(image_noise_sigma(noisy) == Approx(sigma).epsilon(0.2));
  }
  CHECK(image_noise_sigma(a) < 1.0);
}

TEST_CASE("refine_patch under sensor noise settles when told the noise", "[tracker][patch]") {
  // A weak texture (contrast ~10 gray levels) and noise of sigma 2 in both images.
  cv::Mat a = texture(7), weak;
  a.convertTo(weak, CV_32F, 10.0 / 255.0, 100.0);
  auto noisy = [&](const cv::Mat& img, uint64_t seed) {
    cv::Mat noise(img.size(), CV_32F), out;
    cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
    cv::Mat(img + noise).convertTo(out, CV_8U);
    return out;
  };
  const cv::Mat first = noisy(weak, 1);
  cv::Mat moved;
  cv::warpAffine(weak, moved, cv::Matx23d(1, 0, 2.0, 0, 1, 1.0), weak.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  const cv::Mat second = noisy(moved, 2);
  int settled = 0, settled_blind = 0, near = 0, n = 0;
  for (int y = 40; y < 200; y += 20)
    for (int x = 40; x < 280; x += 20) {
      const auto tmpl = capture_patch(first, Eigen::Vector2f(x, y));
      if (!tmpl) continue;
      ++n;
      tracker::AffineWarp w, blind;
      w.t = blind.t = Eigen::Vector2f(x + 2.3f, y + 0.8f);
      const tracker::RefineOutcome o = refine_patch(*tmpl, second, &w, image_noise_sigma(second));
      settled += o.result == tracker::RefineResult::Converged;
      near += o.result == tracker::RefineResult::Converged && (w.t - Eigen::Vector2f(x + 2, y + 1)).norm() < 1.0f;
      settled_blind += refine_patch(*tmpl, second, &blind).result == tracker::RefineResult::Converged;
    }
  REQUIRE(n > 50);
  CHECK(settled > 0.9 * n);
  CHECK(near > 0.9 * settled);
  CHECK(settled_blind < settled);  // told nothing, it asks for 0.01 px the noise cannot give
}
