#include "stages/tracker/corner_detector.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace dynavins {

std::vector<cv::Point2f> detect_corners(const cv::Mat& gray, const cv::Mat& mask, int max_corners, double quality,
                                        double min_distance) {
  std::vector<cv::Point2f> out;
  if (max_corners <= 0 || gray.empty()) return out;
  cv::Mat eig, peak;
  cv::cornerMinEigenVal(gray, eig, 3, 3);
  double max_val = 0;
  cv::minMaxLoc(eig, nullptr, &max_val, nullptr, nullptr, mask);
  if (max_val <= 0) return out;
  const float thresh = static_cast<float>(quality * max_val);
  cv::dilate(eig, peak, cv::Mat());  // 3x3 local maxima only

  struct Candidate {
    float score;
    int u, v;
  };
  std::vector<Candidate> cand;
  for (int v = 1; v < eig.rows - 1; ++v) {
    const float* e = eig.ptr<float>(v);
    const float* p = peak.ptr<float>(v);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(v);
    for (int u = 1; u < eig.cols - 1; ++u)
      if (e[u] > thresh && e[u] == p[u] && (!m || m[u])) cand.push_back({e[u], u, v});
  }
  // Strongest first; ties broken by position so the result does not depend on the sort.
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
