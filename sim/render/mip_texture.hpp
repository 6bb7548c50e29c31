#pragma once
// A gray albedo texture with its mip pyramid and footprint-filtered (trilinear, anisotropic) sampling,
// so surfaces far away or seen at grazing angles are averaged rather than aliased.
// Texture coordinates (s, r) are normalised to [0, 1] across the quad; row 0 is at r = 0.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace dynavins::sim {

class MipTexture {
 public:
  /// Raw view of one level for the sampler's inner loop.
  struct Level {
    const uint8_t* data = nullptr;  // texel (0, 0); one replicated texel of border on every side
    int w = 0;
    int h = 0;
    size_t step = 0;
    float wf = 0.0f;
    float hf = 0.0f;
  };

  /// Takes a CV_8UC1 albedo image (0..255) and builds the pyramid down to 1x1 (area averaging).
  explicit MipTexture(const cv::Mat& level0);

  int width() const { return levels_[0].w; }
  int height() const { return levels_[0].h; }
  int num_levels() const { return static_cast<int>(levels_.size()); }
  /// Level k as a cv::Mat (shares memory, without the border).
  cv::Mat level_mat(int k) const;
  /// Bytes held by all levels.
  size_t bytes() const;

  /// Bilinear sample of level k at normalised (s, r) in [0, 1] (edge texels extend to the border);
  /// returns 0..255.
  float bilinear(int k, float s, float r) const {
    const Level& L = levels_[k];
    const float x = s * L.wf - 0.5f;
    const float y = r * L.hf - 0.5f;
    // x, y >= -0.5: truncation after a +1 shift is floor without a libm call. The border texels make
    // indices -1 .. w valid, so no clamping is needed.
    const int xi = static_cast<int>(x + 1.0f) - 1;
    const int yi = static_cast<int>(y + 1.0f) - 1;
    const float ax = x - static_cast<float>(xi);
    const float ay = y - static_cast<float>(yi);
    const uint8_t* r0 = L.data + static_cast<ptrdiff_t>(yi) * static_cast<ptrdiff_t>(L.step) + xi;
    const uint8_t* r1 = r0 + L.step;
    const float top = r0[0] + ax * (static_cast<float>(r0[1]) - r0[0]);
    const float bot = r1[0] + ax * (static_cast<float>(r1[1]) - r1[0]);
    return top + ay * (bot - top);
  }

  /// Trilinear sample at a level of detail (log2 of the footprint in level-0 texels).
  float trilinear(float s, float r, float lod) const {
    lod = std::clamp(lod, 0.0f, max_lod_);
    const int k = static_cast<int>(lod);
    const float f = lod - static_cast<float>(k);
    const float a = bilinear(k, s, r);
    if (f < 1.0f / 256.0f || k + 1 >= static_cast<int>(levels_.size())) return a;
    return a + f * (bilinear(k + 1, s, r) - a);
  }

  /// Footprint-filtered sample: (s, r) and their derivatives per pixel step along the image u and v
  /// axes. Takes up to `max_aniso` probes along the footprint's long axis, at the level of its short
  /// axis (the usual GPU anisotropic filter). Levels are blended in the middle half of each octave only
  /// (GPUs' "brilinear" mode): sharper than full trilinear, still continuous in distance.
  float sample(float s, float r, float dsdu, float drdu, float dsdv, float drdv, int max_aniso) const {
    const float W = levels_[0].wf;
    const float H = levels_[0].hf;
    const float lu = std::sqrt(dsdu * W * dsdu * W + drdu * H * drdu * H);
    const float lv = std::sqrt(dsdv * W * dsdv * W + drdv * H * drdv * H);
    float major = lu;
    float minor = lv;
    float as = dsdu;
    float ar = drdu;
    if (lv > lu) {
      major = lv;
      minor = lu;
      as = dsdv;
      ar = drdv;
    }
    int n = 1;
    float level_len = major;
    if (major > 1.0f && major > 1.5f * minor) {  // minified and stretched: probe along the long axis
      const float ratio = std::min(major / std::max(minor, 1e-6f), static_cast<float>(max_aniso));
      n = static_cast<int>(ratio);
      n += static_cast<float>(n) < ratio ? 1 : 0;  // ceil without a libm call
      level_len = major / static_cast<float>(n);
    }
    const float lod = std::clamp(fast_log2(std::max(level_len, 1e-6f)), 0.0f, max_lod_);
    int k = static_cast<int>(lod);
    float f = std::clamp(2.0f * (lod - static_cast<float>(k)) - 0.5f, 0.0f, 1.0f);
    if (f >= 1.0f) {  // upper quarter of the octave: the coarser level alone
      ++k;
      f = 0.0f;
    }
    const bool blend = f > 0.0f;
    auto probe = [&](float ps, float pr) {  // one bilinear fetch, or two blended
      ps = std::clamp(ps, 0.0f, 1.0f);
      pr = std::clamp(pr, 0.0f, 1.0f);
      const float a = bilinear(k, ps, pr);
      return blend ? a + f * (bilinear(k + 1, ps, pr) - a) : a;
    };
    if (n == 1) return probe(s, r);
    float acc = 0.0f;
    const float inv = 1.0f / static_cast<float>(n);
    for (int i = 0; i < n; ++i) {
      const float o = (static_cast<float>(i) + 0.5f) * inv - 0.5f;
      acc += probe(s + o * as, r + o * ar);
    }
    return acc * inv;
  }

 private:
  // log2 to within ~0.005: plenty for choosing a mip level, and several times faster than std::log2.
  static float fast_log2(float x) {
    uint32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    const float e = static_cast<float>(static_cast<int>((bits >> 23) & 255u) - 127);
    bits = (bits & 0x007FFFFFu) | 0x3F800000u;
    float m;
    std::memcpy(&m, &bits, sizeof m);  // mantissa in [1, 2)
    return e + (-0.34484843f * m + 2.02466578f) * m - 0.67487759f;
  }

  std::vector<cv::Mat> mats_;  // levels with their border
  std::vector<Level> levels_;
  float max_lod_ = 0.0f;
};

}  // namespace dynavins::sim
