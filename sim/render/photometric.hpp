#pragma once
// Camera-side photometric effects applied to a rendered gray image: exposure gain and offset drifting
// slowly over time, vignetting, and Gaussian pixel noise. Deterministic in (seed, time, camera index).

#include <cstdint>

#include <opencv2/core/mat.hpp>

namespace dynavins::sim {

struct PhotometricOptions {
  double gain = 1.0;             ///< multiplies the rendered gray
  double offset = 0.0;           ///< gray levels added after the gain (black level)
  double gain_drift = 0.05;      ///< relative amplitude of the slow gain variation (auto exposure)
  double drift_period_s = 25.0;  ///< main period of that variation [s]
  double noise_sigma = 1.5;      ///< Gaussian pixel noise [gray levels]
  double vignetting = 0.0;       ///< relative darkening at the image corners (0 = none)
  uint64_t seed = 0;

  /// Dusk / night: low gain, a raised black level, strong noise and vignetting.
  static PhotometricOptions night();
};

/// Effective gain at time t: gain * (1 + drift(t)), drift a smooth seed-dependent mix of two sines.
double photometric_gain(const PhotometricOptions& options, double t);

/// Applies the effects to a CV_8UC1 image; `camera_index` decorrelates the noise of stereo views.
cv::Mat apply_photometric(const cv::Mat& gray, const PhotometricOptions& options, double t, int camera_index = 0);

}  // namespace dynavins::sim
