#include "sim/render/ground_texture.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>

#include "sim/render/parallel_rows.hpp"
#include "sim/render/random.hpp"
#include "sim/render/texture_canvas.hpp"

namespace dynavins::sim {
namespace {

using V2 = Eigen::Vector2d;
constexpr double kPi = 3.141592653589793;
constexpr double kFeatureCell = 4.0;  // world cells that seed the scattered features

struct RoadHit {
  int road = -1;
  double dist = std::numeric_limits<double>::infinity();  // to the centre line (capsule)
  double along = 0.0;
  double across = 0.0;  // signed, left of a->b positive
  bool inside_segment = false;
};

RoadHit nearest_road(const GroundLayout& g, const std::vector<int>& candidates, const V2& p) {
  RoadHit best;
  for (int k : candidates) {
    const Road& r = g.roads[k];
    const V2 d = r.b - r.a;
    const double len = d.norm();
    if (len <= 0.0) continue;
    const V2 e = d / len;
    const V2 q = p - r.a;
    const double along = q.dot(e);
    const double across = e.x() * q.y() - e.y() * q.x();
    const bool inside = along >= 0.0 && along <= len;
    const double dist = inside ? std::abs(across) : (along < 0.0 ? q.norm() : (p - r.b).norm());
    if (dist < best.dist) best = RoadHit{k, dist, along, across, inside};
  }
  return best;
}

GroundClass class_of(const GroundLayout& g, const RoadHit& h) {
  if (g.roads.empty()) return GroundClass::Road;
  if (h.road < 0) return GroundClass::Verge;
  const double half = 0.5 * g.roads[h.road].width_m;
  if (h.dist < half) return GroundClass::Road;
  if (h.dist < half + g.curb_m) return GroundClass::Curb;
  if (h.dist < half + g.curb_m + g.sidewalk_m) return GroundClass::Sidewalk;
  return GroundClass::Verge;
}

std::vector<int> all_roads(const GroundLayout& g) {
  std::vector<int> v(g.roads.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<int>(i);
  return v;
}

float f01(double v) { return static_cast<float>(std::clamp(v, 0.02, 0.76)); }

// Scattered features of one world cell, chosen by the ground class where each lands.
void paint_cell_features(TextureCanvas& c, const GroundLayout& g, const std::vector<int>& roads, int64_t i,
                         int64_t j) {
  Rng rng(hash3(g.seed ^ 0xFEA7FEA7ull, i, j));
  const V2 origin(i * kFeatureCell, j * kFeatureCell);
  const int n = rng.uniform_int(3, 6);
  for (int k = 0; k < n; ++k) {
    const V2 p = origin + kFeatureCell * V2(rng.uniform(), rng.uniform());
    const RoadHit hit = nearest_road(g, roads, p);
    const GroundClass cls = class_of(g, hit);
    double road_angle = 0.0;
    if (hit.road >= 0) {
      const V2 d = g.roads[hit.road].b - g.roads[hit.road].a;
      road_angle = std::atan2(d.y(), d.x());
    }
    const double u = rng.uniform();
    if (cls == GroundClass::Road) {
      if (u < 0.2) {  // repair patch with a dark seam
        const V2 half(rng.uniform(0.3, 1.6), rng.uniform(0.25, 1.0));
        const double a = road_angle + rng.uniform(-0.08, 0.08);
        c.fill_rotated_rect(p, half, a, f01(0.3 + rng.uniform(-0.1, 0.07)), 0.85f);
        const V2 ex(std::cos(a), std::sin(a)), ey(-ex.y(), ex.x());
        const V2 q0 = p - half.x() * ex - half.y() * ey, q1 = p + half.x() * ex - half.y() * ey;
        const V2 q2 = p + half.x() * ex + half.y() * ey, q3 = p - half.x() * ex + half.y() * ey;
        c.stroke({q0, q1, q2, q3, q0}, 0.02, 0.12f, 0.6f);
      } else if (u < 0.55) {  // crack: a random walk
        std::vector<V2> pts{p};
        double dir = rng.uniform(0.0, 2.0 * kPi);
        const int segs = rng.uniform_int(6, 20);
        for (int s = 0; s < segs; ++s) {
          dir += rng.uniform(-0.7, 0.7);
          pts.push_back(pts.back() + rng.uniform(0.08, 0.3) * V2(std::cos(dir), std::sin(dir)));
        }
        c.stroke(pts, rng.uniform(0.01, 0.025), 0.1f, 0.85f);
      } else if (u < 0.9) {  // oil / water stain
        c.fill_ellipse(p, rng.uniform(0.1, 0.7), rng.uniform(0.08, 0.5), rng.uniform(0.0, kPi),
                       f01(rng.uniform(0.12, 0.2)), static_cast<float>(rng.uniform(0.25, 0.55)));
      } else if (u < 0.95) {  // manhole cover
        const double r = 0.32;
        c.fill_ellipse(p, r + 0.04, r + 0.04, 0.0, 0.4f);
        c.fill_ellipse(p, r, r, 0.0, 0.17f);
        for (int s = 0; s < 4; ++s) {
          const double a = rng.uniform(0.0, kPi);
          const V2 e(std::cos(a), std::sin(a));
          c.stroke({p - 0.8 * r * e, p + 0.8 * r * e}, 0.02, 0.3f);
        }
      } else {  // light debris
        c.fill_ellipse(p, rng.uniform(0.03, 0.12), rng.uniform(0.02, 0.08), rng.uniform(0.0, kPi),
                       f01(rng.uniform(0.45, 0.7)));
      }
    } else if (cls == GroundClass::Sidewalk || cls == GroundClass::Curb) {
      for (int s = 0; s < 6; ++s) {  // chewing gum, leaves
        const V2 q = p + V2(rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6));
        c.fill_ellipse(q, rng.uniform(0.01, 0.04), rng.uniform(0.01, 0.03), rng.uniform(0.0, kPi),
                       f01(rng.chance(0.6) ? rng.uniform(0.12, 0.25) : rng.uniform(0.55, 0.72)), 0.8f);
      }
      if (u < 0.3) {
        c.fill_ellipse(p, rng.uniform(0.15, 0.6), rng.uniform(0.1, 0.4), rng.uniform(0.0, kPi),
                       f01(rng.uniform(0.25, 0.35)), static_cast<float>(rng.uniform(0.2, 0.5)));
      }
    } else {  // verge
      if (u < 0.25) {  // bush: dark mass with lit leaves
        const double r = rng.uniform(0.4, 1.2);
        c.fill_ellipse(p, r, r * rng.uniform(0.6, 1.0), rng.uniform(0.0, kPi), f01(rng.uniform(0.08, 0.15)));
        for (int s = 0; s < 25; ++s) {
          const V2 q = p + r * 0.8 * V2(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
          c.fill_ellipse(q, rng.uniform(0.03, 0.08), rng.uniform(0.02, 0.05), rng.uniform(0.0, kPi),
                         f01(rng.uniform(0.2, 0.4)));
        }
      }
      for (int s = 0; s < 8; ++s) {  // stones
        const V2 q = p + V2(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
        c.fill_ellipse(q, rng.uniform(0.02, 0.1), rng.uniform(0.015, 0.07), rng.uniform(0.0, kPi),
                       f01(rng.uniform(0.4, 0.68)));
      }
    }
  }
}

}  // namespace

GroundClass classify_ground(const GroundLayout& layout, const Eigen::Vector2d& p) {
  return class_of(layout, nearest_road(layout, all_roads(layout), p));
}

cv::Mat paint_ground(const GroundLayout& g, double x0, double y0, double w, double h, double texel) {
  const int cols = std::max(1, static_cast<int>(std::lround(w / texel)));
  const int rows = std::max(1, static_cast<int>(std::lround(h / texel)));
  TextureCanvas c(cols, rows, texel, x0, y0);

  // Roads that can influence this tile (their outer sidewalk edge reaches it).
  std::vector<int> roads;
  for (size_t k = 0; k < g.roads.size(); ++k) {
    const Road& r = g.roads[k];
    const double reach = 0.5 * r.width_m + g.curb_m + g.sidewalk_m + 1.0;
    const double xa = std::min(r.a.x(), r.b.x()) - reach, xb = std::max(r.a.x(), r.b.x()) + reach;
    const double ya = std::min(r.a.y(), r.b.y()) - reach, yb = std::max(r.a.y(), r.b.y()) + reach;
    if (xb >= x0 && xa <= x0 + w && yb >= y0 && ya <= y0 + h) roads.push_back(static_cast<int>(k));
  }
  const bool any_roads = !g.roads.empty();

  const uint64_t key = mix64(g.seed ^ 0x6A0B0D);
  const cv::Mat1f verge_mix = c.noise_field(mix64(key + 1), 6.0);  // grass vs gravel
  const cv::Mat1f mid = c.noise_field(mix64(key + 2), 0.35);
  const cv::Mat1f fine = c.noise_field(mix64(key + 3), 0.07);
  cv::Mat1b cls(rows, cols);
  cv::Mat1f marking(rows, cols, 0.0f);
  cv::Mat1f& img = c.image();

  parallel_rows(rows, [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      for (int col = 0; col < cols; ++col) {
        const V2 p = c.centre(col, r);
        const RoadHit hit = any_roads ? nearest_road(g, roads, p) : RoadHit{};
        const GroundClass k = any_roads ? class_of(g, hit) : GroundClass::Road;
        cls(r, col) = static_cast<uint8_t>(k);
        const float m = mid(r, col), f = fine(r, col);
        float a = 0.0f;
        switch (k) {
          case GroundClass::Road: {
            a = 0.29f + 0.03f * m + 0.035f * f;
            if (hit.road >= 0 && hit.inside_segment) {
              const Road& rd = g.roads[hit.road];
              const double half = 0.5 * rd.width_m, ac = std::abs(hit.across);
              if (ac > half - 0.15) a *= 0.85f;  // gutter
              bool mark = ac > half - 0.34 && ac < half - 0.22;
              if (rd.centre_line && ac < 0.06) {
                const double phase = hash_unit(hash3(g.seed, hit.road, 77)) * 9.0;
                mark = mark || std::fmod(hit.along + phase, 9.0) < 3.0;
              }
              if (mark) marking(r, col) = 1.0f;
            }
            break;
          }
          case GroundClass::Curb:
            a = 0.52f + 0.03f * m + 0.03f * f;
            break;
          case GroundClass::Sidewalk: {
            // Slabs in rows along the road: each row its own slab length and offset, each slab its own
            // tint, so the joints never form a strictly periodic grid.
            const Road& rd = g.roads[hit.road];
            const double d = hit.dist - 0.5 * rd.width_m - g.curb_m;
            const double depth = 0.5;
            const int64_t row = static_cast<int64_t>(std::floor(d / depth));
            const int64_t side = hit.across > 0.0 ? 1 : 0;
            const uint64_t rk = hash3(g.seed ^ 0x51AB, hit.road * 2 + side, row);
            const double len = 0.4 + 0.5 * hash_unit(rk);
            const double s = hit.along + hash_unit(mix64(rk)) * len;
            const double slab = std::floor(s / len);
            const double fu = s - slab * len, fd = d - row * depth;
            const double joint = std::min({fu, len - fu, fd, depth - fd});
            const float tint = 0.1f * (hash_unit(hash3(rk, static_cast<int64_t>(slab), 3)) - 0.5f);
            a = 0.46f + tint + 0.02f * m + 0.03f * f;
            if (joint < 0.009) a *= 0.55f;
            break;
          }
          case GroundClass::Verge: {
            const bool grass = verge_mix(r, col) > -0.15f;
            a = grass ? 0.22f + 0.06f * m + 0.09f * f : 0.4f + 0.05f * m + 0.06f * f;
            break;
          }
        }
        img(r, col) = a;
      }
    }
  });

  c.add_fractal_noise(mix64(key + 4), 8.0, 3, 0.035f);
  // Aggregate: small sharp-edged light and dark specks (grass tufts on the verge).
  c.add_blotches(mix64(key + 5), 0.05, 0.55, 0.42f, 0.45f);
  c.add_blotches(mix64(key + 6), 0.12, 0.5, 0.12f, 0.35f);

  // Scattered features from the world cells overlapping this tile (with margin for their extent).
  const double margin = 3.0;
  const int64_t i0 = static_cast<int64_t>(std::floor((x0 - margin) / kFeatureCell));
  const int64_t i1 = static_cast<int64_t>(std::floor((x0 + w + margin) / kFeatureCell));
  const int64_t j0 = static_cast<int64_t>(std::floor((y0 - margin) / kFeatureCell));
  const int64_t j1 = static_cast<int64_t>(std::floor((y0 + h + margin) / kFeatureCell));
  const std::vector<int> all = all_roads(g);
  for (int64_t j = j0; j <= j1; ++j) {
    for (int64_t i = i0; i <= i1; ++i) paint_cell_features(c, g, all, i, j);
  }

  // Worn white markings on top.
  for (int r = 0; r < rows; ++r) {
    for (int col = 0; col < cols; ++col) {
      const float m = marking(r, col);
      if (m > 0.0f) {
        const float wear = std::clamp(0.8f + 0.4f * fine(r, col), 0.0f, 1.0f);
        img(r, col) += wear * (0.7f - img(r, col));
      }
    }
  }
  c.add_grain(mix64(key + 7), 0.04f);
  return c.to_u8();
}

}  // namespace dynavins::sim
