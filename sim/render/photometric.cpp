#include "sim/render/photometric.hpp"

#include <cmath>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "sim/render/random.hpp"

namespace dynavins::sim {

PhotometricOptions PhotometricOptions::night() {
  PhotometricOptions o;
  o.gain = 0.3;
  o.offset = 4.0;
  o.gain_drift = 0.08;
  o.noise_sigma = 3.0;
  o.vignetting = 0.35;
  return o;
}

double photometric_gain(const PhotometricOptions& o, double t) {
  constexpr double kTwoPi = 6.283185307179586;
  const double ph1 = kTwoPi * hash_unit(mix64(o.seed ^ 0xD41F7));
  const double ph2 = kTwoPi * hash_unit(mix64(o.seed ^ 0xD41F8));
  const double drift = 0.7 * std::sin(kTwoPi * t / o.drift_period_s + ph1) +
                       0.3 * std::sin(kTwoPi * t / (0.37 * o.drift_period_s) + ph2);
  return o.gain * (1.0 + o.gain_drift * drift);
}

cv::Mat apply_photometric(const cv::Mat& gray, const PhotometricOptions& o, double t, int camera_index) {
  if (gray.type() != CV_8UC1) throw std::invalid_argument("apply_photometric: expects CV_8UC1");
  const double gain = photometric_gain(o, t);
  cv::Mat1f noise(gray.size(), 0.0f);
  if (o.noise_sigma > 0.0) {
    // Seeded from the time stamp, not from a running state: a frame renders the same alone or in sequence.
    const auto t_us = static_cast<int64_t>(std::llround(t * 1e6));
    cv::RNG rng(hash3(o.seed, t_us, camera_index));
    rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
  }
  const double cx = 0.5 * (gray.cols - 1), cy = 0.5 * (gray.rows - 1);
  const double inv_r2 = 1.0 / (cx * cx + cy * cy);
  cv::Mat out(gray.size(), CV_8UC1);
  for (int v = 0; v < gray.rows; ++v) {
    const uint8_t* in = gray.ptr<uint8_t>(v);
    const float* nz = noise.ptr<float>(v);
    uint8_t* dst = out.ptr<uint8_t>(v);
    const double dy2 = (v - cy) * (v - cy);
    for (int u = 0; u < gray.cols; ++u) {
      const double r2 = ((u - cx) * (u - cx) + dy2) * inv_r2;  // 1 at the corners
      const double vig = 1.0 - o.vignetting * r2;  // quadratic fall-off toward the corners
      const double val = in[u] * gain * vig + o.offset + nz[u];
      dst[u] = cv::saturate_cast<uint8_t>(val);
    }
  }
  return out;
}

}  // namespace dynavins::sim
