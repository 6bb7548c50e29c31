// Procedural textures (paint_surface, paint_ground, TextureCanvas): deterministic, seamless, and rich in
// unambiguous corners at the scale a camera sees them.

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/render/ground_texture.hpp"
#include "sim/render/procedural_texture.hpp"
#include "sim/render/texture_canvas.hpp"

using namespace dynavins::sim;

namespace {

// The texture as a camera ~10 m away sees it: `metres_per_px` per pixel (area-averaged).
cv::Mat at_viewing_scale(const cv::Mat& tex, double texel_m, double metres_per_px) {
  cv::Mat out;
  const double f = texel_m / metres_per_px;
  cv::resize(tex, out, cv::Size(), f, f, cv::INTER_AREA);
  return out;
}

// Minimum-eigenvalue score (the one goodFeaturesToTrack ranks by) of a plain corner of `contrast` gray
// levels: the weakest corner we count as trackable.
double reference_corner_score(double contrast) {
  cv::Mat ref(32, 32, CV_8UC1, cv::Scalar(100));
  ref(cv::Rect(16, 16, 16, 16)).setTo(cv::Scalar(100 + contrast));
  cv::Mat eig;
  cv::cornerMinEigenVal(ref, eig, 3, 3);
  double mx = 0.0;
  cv::minMaxLoc(eig, nullptr, &mx);
  return mx;
}

// Share of blocks (block_px square) holding a corner at least as strong as a 12-gray-level step corner.
// An absolute score, so one very strong feature elsewhere does not hide the others. Also counts the
// corners goodFeaturesToTrack returns on the whole image, for the report.
double corner_coverage(const cv::Mat& img, int block_px, int* n_corners) {
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(img, corners, 2000, 0.01, 8);
  *n_corners = static_cast<int>(corners.size());
  cv::Mat eig;
  cv::cornerMinEigenVal(img, eig, 3, 3);
  const double thr = reference_corner_score(12.0);
  const int bx = img.cols / block_px, by = img.rows / block_px;
  int covered = 0;
  for (int j = 0; j < by; ++j) {
    for (int i = 0; i < bx; ++i) {
      double mx = 0.0;
      cv::minMaxLoc(eig(cv::Rect(i * block_px, j * block_px, block_px, block_px)), nullptr, &mx);
      covered += mx >= thr;
    }
  }
  return bx * by > 0 ? static_cast<double>(covered) / (bx * by) : 0.0;
}

// Share of corners whose 15x15 patch has a second, separate match within +-12 px: a local maximum of
// the normalised cross-correlation above 0.9 away from the true position, cut off from it by a valley
// (the correlation dips by 0.25 or more on the way). That is repeated structure which would let KLT lock
// onto the wrong place. A ridge running out of the true peak along an edge is the aperture problem, not
// repetition, and is not counted.
double ambiguous_corner_share(const cv::Mat& img) {
  const int half = 7, search = 12;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(img, corners, 400, 0.01, 8);
  int ambiguous = 0, tried = 0;
  for (const auto& c : corners) {
    const int x = static_cast<int>(c.x), y = static_cast<int>(c.y);
    if (x < half + search || y < half + search || x >= img.cols - half - search || y >= img.rows - half - search) continue;
    const cv::Mat patch = img(cv::Rect(x - half, y - half, 2 * half + 1, 2 * half + 1));
    const cv::Mat region = img(cv::Rect(x - half - search, y - half - search, 2 * (half + search) + 1,
                                        2 * (half + search) + 1));
    cv::Mat ncc;
    cv::matchTemplate(region, patch, ncc, cv::TM_CCOEFF_NORMED);
    cv::Mat dilated;
    cv::dilate(ncc, dilated, cv::Mat::ones(3, 3, CV_8UC1));
    bool second = false;
    for (int r = 0; r < ncc.rows && !second; ++r) {
      for (int q = 0; q < ncc.cols && !second; ++q) {
        if (std::abs(r - search) <= 2 && std::abs(q - search) <= 2) continue;  // the true peak
        const float v = ncc.at<float>(r, q);
        if (!(v > 0.9f && v >= dilated.at<float>(r, q))) continue;
        float lowest = v;
        const int steps = 4 * std::max(std::abs(r - search), std::abs(q - search));
        for (int k = 1; k < steps; ++k) {
          const double a = static_cast<double>(k) / steps;
          lowest = std::min(lowest, ncc.at<float>(static_cast<int>(std::lround(search + a * (r - search))),
                                                  static_cast<int>(std::lround(search + a * (q - search)))));
        }
        second = lowest < v - 0.25f;
      }
    }
    ++tried;
    if (second) ++ambiguous;
  }
  return tried > 0 ? static_cast<double>(ambiguous) / tried : 1.0;
}

struct KindCase {
  SurfaceKind kind;
  double w, h, texel;
  const char* name;
};

}  // namespace

TEST_CASE("Procedural textures are deterministic in the seed", "[texture][procedural]") {
  SurfaceSpec spec;
  spec.kind = SurfaceKind::Facade;
  spec.width_m = 12.0;
  spec.height_m = 9.0;
  spec.seed = 42;
  const cv::Mat a = paint_surface(spec), b = paint_surface(spec);
  REQUIRE(a.size() == cv::Size(600, 450));
  CHECK(cv::norm(a, b, cv::NORM_INF) == 0.0);
  spec.seed = 43;
  CHECK(cv::norm(a, paint_surface(spec), cv::NORM_L1) / a.total() > 5.0);

  GroundLayout g;
  g.roads.push_back(Road{{-50, 0}, {50, 0}, 8.0, true});
  const cv::Mat g1 = paint_ground(g, -4, -6, 8, 12, 0.02), g2 = paint_ground(g, -4, -6, 8, 12, 0.02);
  CHECK(cv::norm(g1, g2, cv::NORM_INF) == 0.0);

  // Independent of the number of threads painting it.
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  spec.seed = 42;
  const cv::Mat a1 = paint_surface(spec);
  const cv::Mat g3 = paint_ground(g, -4, -6, 8, 12, 0.02);
  cv::setNumThreads(threads);
  CHECK(cv::norm(a, a1, cv::NORM_INF) == 0.0);
  CHECK(cv::norm(g1, g3, cv::NORM_INF) == 0.0);
}

TEST_CASE("Ground tiles painted separately join without a seam", "[texture][procedural]") {
  GroundLayout g;
  g.seed = 5;
  g.roads.push_back(Road{{-50, 1.0}, {50, 1.0}, 7.0, true});
  // One 8 m tile against two 4 m halves: the right half must equal the whole tile's right half except
  // where scattered features are cut differently (none: features are seeded per world cell).
  const cv::Mat whole = paint_ground(g, 0, -4, 8, 8, 0.02);
  const cv::Mat right = paint_ground(g, 4, -4, 4, 8, 0.02);
  cv::Mat diff;
  cv::absdiff(whole(cv::Rect(200, 0, 200, 400)), right, diff);
  cv::Scalar mean = cv::mean(diff);
  INFO("mean |difference| " << mean[0]);
  CHECK(mean[0] < 0.5);
  double worst = 0.0;
  cv::minMaxLoc(diff, nullptr, &worst);
  CHECK(worst <= 2.0);  // rounding of polygon fills at the tile border only
}

TEST_CASE("Ground classes follow the road layout", "[texture][procedural]") {
  GroundLayout g;
  g.roads.push_back(Road{{0, 0}, {100, 0}, 8.0, true});
  CHECK(classify_ground(g, {50, 0}) == GroundClass::Road);
  CHECK(classify_ground(g, {50, -3.9}) == GroundClass::Road);
  CHECK(classify_ground(g, {50, 4.1}) == GroundClass::Curb);
  CHECK(classify_ground(g, {50, -5.5}) == GroundClass::Sidewalk);
  CHECK(classify_ground(g, {50, 9.0}) == GroundClass::Verge);
  CHECK(classify_ground(GroundLayout{}, {1e3, -1e3}) == GroundClass::Road);  // no roads: all asphalt
}

TEST_CASE("Every texture kind gives well-spread, unambiguous corners at viewing scale", "[texture][procedural]") {
  const KindCase cases[] = {
      {SurfaceKind::Facade, 20.0, 12.0, 0.02, "facade"},   {SurfaceKind::Wall, 16.0, 2.5, 0.02, "wall"},
      {SurfaceKind::CarSide, 4.5, 1.5, 0.01, "car side"},  {SurfaceKind::CarBack, 1.8, 1.5, 0.01, "car back"},
      {SurfaceKind::CarFront, 1.8, 1.5, 0.01, "car front"}, {SurfaceKind::TruckSide, 10.0, 3.5, 0.01, "truck side"},
      {SurfaceKind::TruckBack, 2.5, 3.5, 0.01, "truck back"}, {SurfaceKind::TruckFront, 2.5, 3.5, 0.01, "truck front"},
  };
  for (const auto& k : cases) {
   for (uint64_t seed : {9u, 10u, 11u}) {
    SurfaceSpec spec;
    spec.kind = k.kind;
    spec.width_m = k.w;
    spec.height_m = k.h;
    spec.texel_m = k.texel;
    spec.seed = seed;
    // Vehicles are seen close (1 cm/px at ~4.5 m), buildings further (2.5 cm/px at ~11 m).
    const double mpp = k.texel < 0.015 ? 0.01 : 0.025;
    const cv::Mat view = at_viewing_scale(paint_surface(spec), k.texel, mpp);
    int n = 0;
    const int block = static_cast<int>(std::lround(0.5 / mpp)) * (k.texel < 0.015 ? 1 : 2);  // 0.5 m / 1 m
    const double coverage = corner_coverage(view, block, &n);
    const double ambiguous = ambiguous_corner_share(view);
    std::printf("texture %-11s seed %2d %4dx%-4d px: %4d corners, %.0f%% of %.1f m blocks with a corner, %.1f%% ambiguous corners\n",
                k.name, static_cast<int>(seed), view.cols, view.rows, n, 100.0 * coverage, block * mpp, 100.0 * ambiguous);
    INFO(k.name << " seed " << seed);
    CHECK(coverage > 0.9);
    CHECK(ambiguous < 0.1);
   }
  }
  GroundLayout g;
  g.roads.push_back(Road{{-50, 0}, {50, 0}, 8.0, true});
  const cv::Mat ground = paint_ground(g, -5, -12, 12, 24, 0.02);  // road, curbs, sidewalks, verges
  const cv::Mat view = at_viewing_scale(ground, 0.02, 0.025);
  int n = 0;
  const double coverage = corner_coverage(view, 40, &n);
  const double ambiguous = ambiguous_corner_share(view);
  std::printf("texture %-11s %4dx%-4d px: %4d corners, %.0f%% of 1.0 m blocks with a corner, %.1f%% ambiguous corners\n",
              "ground", view.cols, view.rows, n, 100.0 * coverage, 100.0 * ambiguous);
  CHECK(coverage > 0.9);
  CHECK(ambiguous < 0.1);
}

TEST_CASE("The repetition check flags a periodic texture (control)", "[texture][procedural]") {
  // Squares on a 6 px pitch with mild noise: what the textures must not look like.
  cv::Mat img(300, 300, CV_8UC1);
  cv::RNG rng(2);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c)
      img.at<uint8_t>(r, c) = cv::saturate_cast<uint8_t>(((r / 3 + c / 3) % 2 ? 160 : 90) + rng.gaussian(3.0));
  const double ambiguous = ambiguous_corner_share(img);
  std::printf("periodic control: %.0f%% ambiguous corners\n", 100.0 * ambiguous);
  CHECK(ambiguous > 0.5);
}

TEST_CASE("The corner coverage check fails on grain and smooth noise alone (control)", "[texture][procedural]") {
  // The textures' fine grain and large-scale noise without any painted structure.
  TextureCanvas c(1000, 500, 0.02, 0.0, 0.0, 0.45f);
  c.add_fractal_noise(3, 4.0, 3, 0.05f);
  c.modulate_fractal_noise(4, 2.0, 6, 0.07f);
  c.add_grain(5, 0.035f);
  const cv::Mat view = at_viewing_scale(c.to_u8(), 0.02, 0.025);
  int n = 0;
  const double coverage = corner_coverage(view, 40, &n);
  std::printf("grain-only control: %.0f%% of 1.0 m blocks with a corner\n", 100.0 * coverage);
  CHECK(coverage < 0.5);
}

TEST_CASE("TextureCanvas: value noise is smooth, centred and bounded", "[texture][procedural]") {
  TextureCanvas c(400, 300, 0.02);
  const cv::Mat1f n = c.noise_field(77, 0.5);
  double lo = 0, hi = 0;
  cv::minMaxLoc(n, &lo, &hi);
  CHECK(lo >= -1.0);
  CHECK(hi <= 1.0);
  CHECK(std::abs(cv::mean(n)[0]) < 0.15);
  // Neighbouring texels differ by little compared to the range (25 texels per cell).
  cv::Mat dx;
  cv::absdiff(n(cv::Rect(1, 0, 399, 300)), n(cv::Rect(0, 0, 399, 300)), dx);
  double worst = 0;
  cv::minMaxLoc(dx, nullptr, &worst);
  CHECK(worst < 0.2);
}
