#include "sim/render/texture_canvas.hpp"

#include "sim/render/parallel_rows.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/render/random.hpp"

namespace dynavins::sim {
namespace {

constexpr int kShift = 4;  // sub-texel precision of the OpenCV polygon fill
constexpr double kTwoPi = 6.283185307179586;

inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }  // C2 quintic

}  // namespace

TextureCanvas::TextureCanvas(int cols, int rows, double texel_m, double x0_m, double y0_m, float fill)
    : img_(std::max(rows, 1), std::max(cols, 1), fill), texel_(texel_m), x0_(x0_m), y0_(y0_m) {}

template <class Draw>
void TextureCanvas::blend_region(double xa, double ya, double xb, double yb, float value, float alpha,
                                 Draw draw) {
  const int c0 = std::max(0, static_cast<int>(std::floor((std::min(xa, xb) - x0_) / texel_)) - 1);
  const int c1 = std::min(img_.cols, static_cast<int>(std::ceil((std::max(xa, xb) - x0_) / texel_)) + 1);
  const int r0 = std::max(0, static_cast<int>(std::floor((std::min(ya, yb) - y0_) / texel_)) - 1);
  const int r1 = std::min(img_.rows, static_cast<int>(std::ceil((std::max(ya, yb) - y0_) / texel_)) + 1);
  if (c1 <= c0 || r1 <= r0) return;
  cv::Mat1b mask(r1 - r0, c1 - c0, static_cast<uint8_t>(0));
  // Metric -> fixed-point texel-centre coordinates inside the mask.
  auto to_pt = [&](const Eigen::Vector2d& p) {
    const double cx = (p.x() - x0_) / texel_ - 0.5 - c0;
    const double cy = (p.y() - y0_) / texel_ - 0.5 - r0;
    return cv::Point(static_cast<int>(std::lround(cx * (1 << kShift))),
                     static_cast<int>(std::lround(cy * (1 << kShift))));
  };
  draw(mask, to_pt);
  for (int r = 0; r < mask.rows; ++r) {
    const uint8_t* m = mask.ptr<uint8_t>(r);
    float* px = img_.ptr<float>(r + r0) + c0;
    for (int c = 0; c < mask.cols; ++c) {
      if (m[c]) px[c] += alpha * (value - px[c]);
    }
  }
}

void TextureCanvas::fill_rect(double xa, double ya, double xb, double yb, float value, float alpha) {
  fill_polygon({{xa, ya}, {xb, ya}, {xb, yb}, {xa, yb}}, value, alpha);
}

void TextureCanvas::fill_rotated_rect(const Eigen::Vector2d& c, const Eigen::Vector2d& half, double angle,
                                      float value, float alpha) {
  const Eigen::Vector2d ex(std::cos(angle), std::sin(angle));
  const Eigen::Vector2d ey(-ex.y(), ex.x());
  fill_polygon({c - half.x() * ex - half.y() * ey, c + half.x() * ex - half.y() * ey,
                c + half.x() * ex + half.y() * ey, c - half.x() * ex + half.y() * ey},
               value, alpha);
}

void TextureCanvas::fill_polygon(const std::vector<Eigen::Vector2d>& pts, float value, float alpha) {
  if (pts.size() < 3) return;
  double xa = pts[0].x(), xb = xa, ya = pts[0].y(), yb = ya;
  for (const auto& p : pts) {
    xa = std::min(xa, p.x());
    xb = std::max(xb, p.x());
    ya = std::min(ya, p.y());
    yb = std::max(yb, p.y());
  }
  blend_region(xa, ya, xb, yb, value, alpha, [&](cv::Mat1b& mask, auto to_pt) {
    std::vector<cv::Point> poly;
    poly.reserve(pts.size());
    for (const auto& p : pts) poly.push_back(to_pt(p));
    const cv::Point* data = poly.data();
    const int n = static_cast<int>(poly.size());
    cv::fillPoly(mask, &data, &n, 1, cv::Scalar(255), cv::LINE_8, kShift);
  });
}

void TextureCanvas::fill_ellipse(const Eigen::Vector2d& c, double ax, double ay, double angle, float value,
                                 float alpha) {
  const int n = std::clamp(static_cast<int>(kTwoPi * std::max(ax, ay) / (2.0 * texel_)), 12, 96);
  const double ca = std::cos(angle), sa = std::sin(angle);
  std::vector<Eigen::Vector2d> pts;
  pts.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double th = kTwoPi * i / n;
    const double ex = ax * std::cos(th), ey = ay * std::sin(th);
    pts.emplace_back(c.x() + ca * ex - sa * ey, c.y() + sa * ex + ca * ey);
  }
  fill_polygon(pts, value, alpha);
}

void TextureCanvas::stroke(const std::vector<Eigen::Vector2d>& pts, double width_m, float value, float alpha) {
  if (pts.size() < 2) return;
  double xa = pts[0].x(), xb = xa, ya = pts[0].y(), yb = ya;
  for (const auto& p : pts) {
    xa = std::min(xa, p.x());
    xb = std::max(xb, p.x());
    ya = std::min(ya, p.y());
    yb = std::max(yb, p.y());
  }
  const double m = width_m;
  const int thick = std::max(1, static_cast<int>(std::lround(width_m / texel_)));
  blend_region(xa - m, ya - m, xb + m, yb + m, value, alpha, [&](cv::Mat1b& mask, auto to_pt) {
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      cv::line(mask, to_pt(pts[i]), to_pt(pts[i + 1]), cv::Scalar(255), thick, cv::LINE_8, kShift);
    }
  });
}

cv::Mat1f TextureCanvas::noise_field(uint64_t key, double cell_m) const {
  // Large cells are smooth at the texel scale: evaluate them exactly on a coarser grid (>= 12 samples
  // per cell, aligned to global texel indices so neighbouring tiles share the samples) and interpolate
  // bilinearly. The error is well under 1% of the amplitude and it saves most of the texture build time.
  const int step = std::max(1, static_cast<int>(cell_m / texel_ / 12.0));
  if (step > 1) {
    auto floor_div = [](int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
    const int64_t gc0 = std::llround(x0_ / texel_), gr0 = std::llround(y0_ / texel_);
    const int64_t k0 = floor_div(gc0, step), k1 = floor_div(gc0 + img_.cols - 1, step) + 1;
    const int64_t l0 = floor_div(gr0, step), l1 = floor_div(gr0 + img_.rows - 1, step) + 1;
    // A canvas whose texel centres are the sample points (global texel centres k * step).
    const double big = step * texel_;
    const TextureCanvas coarse(static_cast<int>(k1 - k0 + 1), static_cast<int>(l1 - l0 + 1), big,
                               k0 * big + 0.5 * texel_ - 0.5 * big, l0 * big + 0.5 * texel_ - 0.5 * big);
    const cv::Mat1f g = coarse.noise_field(key, cell_m);
    std::vector<int> ci(static_cast<size_t>(img_.cols));
    std::vector<float> cw(static_cast<size_t>(img_.cols));
    for (int c = 0; c < img_.cols; ++c) {
      const int64_t gc = gc0 + c;
      ci[c] = static_cast<int>(floor_div(gc, step) - k0);
      cw[c] = static_cast<float>(gc - floor_div(gc, step) * step) / static_cast<float>(step);
    }
    cv::Mat1f out(img_.rows, img_.cols);
    for (int r = 0; r < img_.rows; ++r) {
      const int64_t gr = gr0 + r;
      const int j = static_cast<int>(floor_div(gr, step) - l0);
      const float wy = static_cast<float>(gr - floor_div(gr, step) * step) / static_cast<float>(step);
      const float* G0 = g.ptr<float>(j);
      const float* G1 = g.ptr<float>(j + 1);
      float* o = out.ptr<float>(r);
      for (int c = 0; c < img_.cols; ++c) {
        const int i = ci[c];
        const float top = G0[i] + cw[c] * (G0[i + 1] - G0[i]);
        const float bot = G1[i] + cw[c] * (G1[i + 1] - G1[i]);
        o[c] = top + wy * (bot - top);
      }
    }
    return out;
  }
  const double ang = kTwoPi * hash_unit(mix64(key ^ 0x5bd1e995ull));
  const double ca = std::cos(ang) / cell_m, sa = std::sin(ang) / cell_m;
  // Lattice coordinates a = R x / cell are affine in (col, row).
  const Eigen::Vector2d p00 = centre(0, 0);
  const double a00 = ca * p00.x() + sa * p00.y(), b00 = -sa * p00.x() + ca * p00.y();
  const double dac = ca * texel_, dar = sa * texel_, dbc = -sa * texel_, dbr = ca * texel_;
  const double cm = img_.cols - 1, rm = img_.rows - 1;
  const double as[4] = {a00, a00 + dac * cm, a00 + dar * rm, a00 + dac * cm + dar * rm};
  const double bs[4] = {b00, b00 + dbc * cm, b00 + dbr * rm, b00 + dbc * cm + dbr * rm};
  const int64_t ia0 = static_cast<int64_t>(std::floor(*std::min_element(as, as + 4))) - 1;
  const int64_t ib0 = static_cast<int64_t>(std::floor(*std::min_element(bs, bs + 4))) - 1;
  const int na = static_cast<int>(std::floor(*std::max_element(as, as + 4)) - ia0) + 3;
  const int nb = static_cast<int>(std::floor(*std::max_element(bs, bs + 4)) - ib0) + 3;
  cv::Mat1f lattice(nb, na);
  for (int j = 0; j < nb; ++j) {
    float* L = lattice.ptr<float>(j);
    for (int i = 0; i < na; ++i) L[i] = 2.0f * hash_unit(hash3(key, ia0 + i, ib0 + j)) - 1.0f;
  }
  // Lattice coordinates relative to the cached block are >= 1, so truncation is floor; single
  // precision is ample for them (they stay below a few thousand cells).
  const float la0 = static_cast<float>(a00 - static_cast<double>(ia0));
  const float lb0 = static_cast<float>(b00 - static_cast<double>(ib0));
  const float fdac = static_cast<float>(dac), fdar = static_cast<float>(dar);
  const float fdbc = static_cast<float>(dbc), fdbr = static_cast<float>(dbr);
  cv::Mat1f out(img_.rows, img_.cols);
  parallel_rows(img_.rows, [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      float* o = out.ptr<float>(r);
      const float ar = la0 + fdar * static_cast<float>(r);
      const float br = lb0 + fdbr * static_cast<float>(r);
      for (int c = 0; c < img_.cols; ++c) {
        const float a = ar + fdac * static_cast<float>(c);
        const float b = br + fdbc * static_cast<float>(c);
        const int i = static_cast<int>(a);
        const int j = static_cast<int>(b);
        const float u = fade(a - static_cast<float>(i));
        const float v = fade(b - static_cast<float>(j));
        const float* L0 = lattice.ptr<float>(j) + i;
        const float* L1 = lattice.ptr<float>(j + 1) + i;
        const float top = L0[0] + u * (L0[1] - L0[0]);
        const float bot = L1[0] + u * (L1[1] - L1[0]);
        o[c] = top + v * (bot - top);
      }
    }
  });
  return out;
}

void TextureCanvas::add_fractal_noise(uint64_t key, double cell_m, int octaves, float amplitude,
                                      float persistence) {
  float amp = amplitude;
  for (int o = 0; o < octaves; ++o, cell_m *= 0.5, amp *= persistence) {
    if (cell_m < 1.5 * texel_) break;  // finer than the texels: that is grain's job
    cv::scaleAdd(noise_field(mix64(key + static_cast<uint64_t>(o)), cell_m), amp, img_, img_);
  }
}

void TextureCanvas::modulate_fractal_noise(uint64_t key, double cell_m, int octaves, float amplitude,
                                           float persistence) {
  cv::Mat1f sum(img_.size(), 0.0f);
  float amp = amplitude;
  for (int o = 0; o < octaves; ++o, cell_m *= 0.5, amp *= persistence) {
    if (cell_m < 1.5 * texel_) break;
    cv::scaleAdd(noise_field(mix64(key + static_cast<uint64_t>(o)), cell_m), amp, sum, sum);
  }
  sum += 1.0f;
  img_ = img_.mul(sum);
}

namespace {

// Patch weight in [0, 1]: a narrow ramp above the threshold of a noise field with ragged outlines.
cv::Mat1f blotch_weights(const TextureCanvas& c, uint64_t key, double cell_m, float threshold) {
  cv::Mat1f f = c.noise_field(key, cell_m);
  if (cell_m * 0.33 >= 1.5 * c.texel()) {  // ragged outlines rather than smooth blobs
    cv::scaleAdd(c.noise_field(mix64(key + 1), cell_m * 0.33), 0.35f, f, f);
  }
  const float inv_w = 1.0f / 0.06f;
  for (int r = 0; r < f.rows; ++r) {
    float* p = f.ptr<float>(r);
    for (int col = 0; col < f.cols; ++col) p[col] = std::clamp((p[col] - threshold) * inv_w, 0.0f, 1.0f);
  }
  return f;
}

}  // namespace

void TextureCanvas::add_blotches(uint64_t key, double cell_m, float threshold, float value, float alpha) {
  const cv::Mat1f w = blotch_weights(*this, key, cell_m, threshold);
  for (int r = 0; r < img_.rows; ++r) {
    const float* wr = w.ptr<float>(r);
    float* p = img_.ptr<float>(r);
    for (int c = 0; c < img_.cols; ++c) p[c] += alpha * wr[c] * (value - p[c]);
  }
}

void TextureCanvas::scale_blotches(uint64_t key, double cell_m, float threshold, float factor, float alpha) {
  const cv::Mat1f w = blotch_weights(*this, key, cell_m, threshold);
  for (int r = 0; r < img_.rows; ++r) {
    const float* wr = w.ptr<float>(r);
    float* p = img_.ptr<float>(r);
    for (int c = 0; c < img_.cols; ++c) p[c] *= 1.0f + alpha * wr[c] * (factor - 1.0f);
  }
}

void TextureCanvas::add_grain(uint64_t key, float amplitude) {
  const int64_t gc0 = static_cast<int64_t>(std::llround(x0_ / texel_));
  const int64_t gr0 = static_cast<int64_t>(std::llround(y0_ / texel_));
  parallel_rows(img_.rows, [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      float* p = img_.ptr<float>(r);
      const uint64_t row_key = hash3(key, gr0 + r, 0x9e37);
      for (int c = 0; c < img_.cols; ++c) {
        const uint64_t h = mix64(row_key + static_cast<uint64_t>(gc0 + c));
        // Two uniforms summed: a triangular, centred grain.
        const float g = hash_unit(h) + static_cast<float>(h & 0xFFFFFF) * (1.0f / 16777216.0f) - 1.0f;
        p[c] += amplitude * g;
      }
    }
  });
}

cv::Mat TextureCanvas::to_u8(float lo, float hi) const {
  cv::Mat1f clamped;
  cv::max(img_, lo, clamped);
  cv::min(clamped, hi, clamped);
  cv::Mat out;
  clamped.convertTo(out, CV_8U, 255.0);
  return out;
}

}  // namespace dynavins::sim
