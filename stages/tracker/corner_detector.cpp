#include "stages/tracker/corner_detector.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

namespace dynavins::tracker {

namespace {

struct Candidate {
  float score;
  int u, v;
};

/// Side of the square tiles the mask is cut into: the response is computed only on the bounding box
/// of each tile's free pixels (the kept tracks' discs cover most of the image).
constexpr int kTile = 32;

/// Index of pixel i on an axis of n pixels under OpenCV's default border (reflect-101).
int reflect(int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); }

/// cv::cornerMinEigenVal(gray, 3, 3) over `r` only, into s->eig, from the image's derivatives s->dx,
/// s->dy scaled as it scales them. The same operations in the same order (float products, box sums in
/// double, OpenCV's eigenvalue formula), so the same numbers bar its running column sum: that one
/// rounds differently, by at most ~1e-11 on EuRoC frames, far below any corner threshold.
/// Plain loops instead of its Sobel / boxFilter engine calls, whose set-up cost is what a small rect
/// pays. s->products holds dx^2, dx dy, dy^2 of one row over the rect's columns +-1, s->rows their
/// 3-wide horizontal sums (a ring of three rows).
void minimum_eigenvalue(const cv::Rect& r, CornerScratch* s) {
  const cv::Mat &dx = s->dx, &dy = s->dy;
  const int w = r.width;
  s->products.resize(3 * static_cast<std::size_t>(w + 2));
  s->rows.resize(9 * static_cast<std::size_t>(w));
  s->terms.resize(2 * static_cast<std::size_t>(w));
  float *pa = s->products.data(), *pb = pa + (w + 2), *pc = pb + (w + 2);
  auto horizontal = [&](int v, double* h) {
    const float *x = dx.ptr<float>(v), *y = dy.ptr<float>(v);
    auto put = [&](int k, int u) { pa[k] = x[u] * x[u], pb[k] = x[u] * y[u], pc[k] = y[u] * y[u]; };
    put(0, reflect(r.x - 1, dx.cols));
    for (int k = 1; k <= w; ++k) put(k, r.x + k - 1);
    put(w + 1, reflect(r.x + w, dx.cols));
    double *ha = h, *hb = h + w, *hc = h + 2 * w;
    for (int k = 0; k < w; ++k) {
      ha[k] = static_cast<double>(pa[k]) + static_cast<double>(pa[k + 1]) + static_cast<double>(pa[k + 2]);
      hb[k] = static_cast<double>(pb[k]) + static_cast<double>(pb[k + 1]) + static_cast<double>(pb[k + 2]);
      hc[k] = static_cast<double>(pc[k]) + static_cast<double>(pc[k + 1]) + static_cast<double>(pc[k + 2]);
    }
  };
  double* ring[3] = {s->rows.data(), s->rows.data() + 3 * w, s->rows.data() + 6 * w};
  horizontal(reflect(r.y - 1, dx.rows), ring[0]);
  horizontal(r.y, ring[1]);
  for (int v = r.y; v < r.br().y; ++v) {
    horizontal(reflect(v + 1, dx.rows), ring[2]);
    const double *h0 = ring[0], *h1 = ring[1], *h2 = ring[2];
    // e = (a + c) - sqrt((a - c)^2 + b^2) in two loops through s->terms: std::sqrt keeps a loop
    // scalar (errno), the SIMD square root is the same IEEE operation.
    float* e = s->eig.ptr<float>(v) + r.x;
    float *trace = s->terms.data(), *radicand = trace + w;
    for (int k = 0; k < w; ++k) {
      const float a = static_cast<float>(h0[k] + h1[k] + h2[k]) * 0.5f;
      const float b = static_cast<float>(h0[w + k] + h1[w + k] + h2[w + k]);
      const float c = static_cast<float>(h0[2 * w + k] + h1[2 * w + k] + h2[2 * w + k]) * 0.5f;
      trace[k] = a + c;
      radicand[k] = (a - c) * (a - c) + b * b;
    }
    int k = 0;
#if CV_SIMD128
    for (; k + cv::v_float32x4::nlanes <= w; k += cv::v_float32x4::nlanes)
      cv::v_store(e + k, cv::v_load(trace + k) - cv::v_sqrt(cv::v_load(radicand + k)));
#endif
    for (; k < w; ++k) e[k] = trace[k] - std::sqrt(radicand[k]);
    std::rotate(ring, ring + 1, ring + 3);
  }
}

}  // namespace

std::vector<cv::Point2f> detect_corners(const cv::Mat& gray, const cv::Mat& mask, int max_corners, double quality,
                                        double min_distance, CornerScratch* scratch) {
  std::vector<cv::Point2f> out;
  if (max_corners <= 0 || gray.empty()) return out;
  CV_Assert(gray.type() == CV_8UC1 && (mask.empty() || mask.size() == gray.size()));

  CornerScratch local;
  CornerScratch& s = scratch ? *scratch : local;
  // cornerMinEigenVal's derivatives: 3x3 Sobel scaled by 1 / (2^(3-1) * 3 (block) * 255 (8-bit)).
  constexpr double kScale = 1.0 / (4.0 * 3.0 * 255.0);
  cv::Sobel(gray, s.dx, CV_32F, 1, 0, 3, kScale);
  cv::Sobel(gray, s.dy, CV_32F, 0, 1, 3, kScale);

  // Most of the image is masked while tracking (each kept track claims a min_distance disc), so the
  // response is computed only round the free pixels: the same numbers as over the whole image.
  const cv::Rect image(0, 0, gray.cols, gray.rows);
  s.eig.create(gray.size(), CV_32F);  // written only round the free boxes, read only there
  const cv::Mat& eig = s.eig;
  std::vector<cv::Rect> boxes;
  float max_val = 0;
  for (int y = 0; y < gray.rows; y += kTile)
    for (int x = 0; x < gray.cols; x += kTile) {
      cv::Rect box = cv::Rect(x, y, kTile, kTile) & image;
      if (!mask.empty()) box = cv::boundingRect(mask(box)) + box.tl();  // empty when all masked
      if (box.empty()) continue;
      // One more pixel round: the 3x3 maximum reads it.
      minimum_eigenvalue(cv::Rect(box.x - 1, box.y - 1, box.width + 2, box.height + 2) & image, &s);
      boxes.push_back(box);
      for (int v = box.y; v < box.br().y; ++v) {
        const float* e = eig.ptr<float>(v);
        const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(v);
        for (int u = box.x; u < box.br().x; ++u)
          if (!m || m[u]) max_val = std::max(max_val, e[u]);
      }
    }
  if (max_val <= 0) return out;
  const float thresh = static_cast<float>(quality * max_val);

  std::vector<Candidate> cand;
  std::vector<uchar> peak(static_cast<std::size_t>(gray.cols));
  for (const cv::Rect& box : boxes) {
    // Local 3x3 maxima (cv::dilate's equality), not on the image's outermost pixels (as goodFeaturesToTrack).
    const int v0 = std::max(1, box.y), v1 = std::min(gray.rows - 1, box.br().y);
    const int u0 = std::max(1, box.x), u1 = std::min(gray.cols - 1, box.br().x);
    for (int v = v0; v < v1; ++v) {
      const float *up = eig.ptr<float>(v - 1), *e = eig.ptr<float>(v), *down = eig.ptr<float>(v + 1);
      const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(v);
      // Branch-free flags first (the compiler vectorises them; on a textured image a branch per pixel
      // mispredicts), then the few set ones.
      for (int u = u0; u < u1; ++u) {
        const float c = e[u];
        peak[u] = (c > thresh) & (!m || m[u]) & (c >= e[u - 1]) & (c >= e[u + 1]) & (c >= up[u - 1]) & (c >= up[u]) &
                  (c >= up[u + 1]) & (c >= down[u - 1]) & (c >= down[u]) & (c >= down[u + 1]);
      }
      for (int u = u0; u < u1; ++u)
        if (peak[u]) cand.push_back({e[u], u, v});
    }
  }
  // Strongest first; ties broken by position so the result does not depend on the order or the tiling.
  // A heap, popped one at a time: the greedy pass below stops early when few corners are wanted (the
  // usual case while tracking), so sorting all the candidates (hundreds to thousands) is wasted.
  const auto weaker = [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score < b.score : (a.v != b.v ? a.v > b.v : a.u > b.u);
  };
  std::make_heap(cand.begin(), cand.end(), weaker);

  // Greedy minimum distance on a grid of min_distance cells: only the 3x3 neighbouring cells can
  // hold a corner closer than min_distance.
  const double d = std::max(1.0, min_distance);
  const double d2 = min_distance * min_distance;
  const int gw = static_cast<int>(std::ceil(gray.cols / d)), gh = static_cast<int>(std::ceil(gray.rows / d));
  std::vector<std::vector<cv::Point2f>> grid(static_cast<std::size_t>(gw * gh));
  for (auto end = cand.end(); end != cand.begin(); --end) {
    std::pop_heap(cand.begin(), end, weaker);
    const Candidate& c = end[-1];
    const int gx = static_cast<int>(c.u / d), gy = static_cast<int>(c.v / d);
    bool free = true;
    for (int y = std::max(0, gy - 1); free && y <= std::min(gh - 1, gy + 1); ++y)
      for (int x = std::max(0, gx - 1); free && x <= std::min(gw - 1, gx + 1); ++x)
        for (const auto& q : grid[static_cast<std::size_t>(y * gw + x)]) {
          const double dx = q.x - c.u, dy = q.y - c.v;
          if (dx * dx + dy * dy < d2) {
            free = false;
            break;
          }
        }
    if (!free) continue;
    const cv::Point2f p(static_cast<float>(c.u), static_cast<float>(c.v));
    grid[static_cast<std::size_t>(gy * gw + gx)].push_back(p);
    out.push_back(p);
    if (static_cast<int>(out.size()) >= max_corners) break;
  }
  return out;
}

}  // namespace dynavins::tracker
