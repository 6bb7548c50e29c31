#include "stages/tracker/corner_detector.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace dynavins {

namespace {

struct Candidate {
  float score;
  int u, v;
};

/// Side of the square tiles the response is computed on; only tiles with a free mask pixel are.
constexpr int kTile = 64;
/// Pixels of context around a tile: the 3x3 Sobel, the 3x3 box of the structure tensor and the 3x3
/// dilation each reach one pixel, so with 3 the tile's interior equals the whole-image computation.
constexpr int kMargin = 3;

/// The minimum-eigenvalue response and its 3x3 maxima over one tile of the image (with context).
struct TileResponse {
  cv::Rect tile;    ///< the tile, in image pixels
  cv::Rect padded;  ///< the tile with its context, clipped to the image
  cv::Mat eig, peak;
};

TileResponse tile_response(const cv::Mat& gray, const cv::Rect& tile) {
  TileResponse r;
  r.tile = tile;
  r.padded = cv::Rect(tile.x - kMargin, tile.y - kMargin, tile.width + 2 * kMargin, tile.height + 2 * kMargin) &
             cv::Rect(0, 0, gray.cols, gray.rows);
  // A submatrix: the Sobel inside reads the real neighbours beyond the padded rect, not a reflection.
  cv::cornerMinEigenVal(gray(r.padded), r.eig, 3, 3);
  cv::dilate(r.eig, r.peak, cv::Mat());
  return r;
}

}  // namespace

std::vector<cv::Point2f> detect_corners(const cv::Mat& gray, const cv::Mat& mask, int max_corners, double quality,
                                        double min_distance) {
  std::vector<cv::Point2f> out;
  if (max_corners <= 0 || gray.empty()) return out;

  // Most of the image is masked while tracking (each kept track claims a min_distance disc), so the
  // response is computed only on the tiles that have a free pixel: the same numbers as over the
  // whole image, a fraction of the cost.
  std::vector<TileResponse> tiles;
  double max_val = 0;
  for (int y = 0; y < gray.rows; y += kTile)
    for (int x = 0; x < gray.cols; x += kTile) {
      const cv::Rect tile = cv::Rect(x, y, kTile, kTile) & cv::Rect(0, 0, gray.cols, gray.rows);
      if (!mask.empty() && cv::countNonZero(mask(tile)) == 0) continue;
      tiles.push_back(tile_response(gray, tile));
      const TileResponse& t = tiles.back();
      const cv::Rect inner = t.tile - t.padded.tl();
      double m = 0;
      cv::minMaxLoc(t.eig(inner), nullptr, &m, nullptr, nullptr, mask.empty() ? cv::noArray() : mask(t.tile));
      max_val = std::max(max_val, m);
    }
  if (max_val <= 0) return out;
  const float thresh = static_cast<float>(quality * max_val);

  std::vector<Candidate> cand;
  for (const TileResponse& t : tiles) {
    // Local 3x3 maxima, not on the image's outermost pixels (as goodFeaturesToTrack).
    const int v0 = std::max(1, t.tile.y), v1 = std::min(gray.rows - 1, t.tile.br().y);
    const int u0 = std::max(1, t.tile.x), u1 = std::min(gray.cols - 1, t.tile.br().x);
    for (int v = v0; v < v1; ++v) {
      const float* e = t.eig.ptr<float>(v - t.padded.y) - t.padded.x;
      const float* p = t.peak.ptr<float>(v - t.padded.y) - t.padded.x;
      const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(v);
      for (int u = u0; u < u1; ++u)
        if (e[u] > thresh && e[u] == p[u] && (!m || m[u])) cand.push_back({e[u], u, v});
    }
  }
  // Strongest first; ties broken by position so the result does not depend on the sort or the tiling.
  std::sort(cand.begin(), cand.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : (a.v != b.v ? a.v < b.v : a.u < b.u);
  });

  // Greedy minimum distance on a grid of min_distance cells: only the 3x3 neighbouring cells can
  // hold a corner closer than min_distance.
  const double d = std::max(1.0, min_distance);
  const double d2 = min_distance * min_distance;
  const int gw = static_cast<int>(std::ceil(gray.cols / d)), gh = static_cast<int>(std::ceil(gray.rows / d));
  std::vector<std::vector<cv::Point2f>> grid(static_cast<std::size_t>(gw * gh));
  for (const Candidate& c : cand) {
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

}  // namespace dynavins
