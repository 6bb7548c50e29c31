#include "sim/render/procedural_texture.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "sim/render/random.hpp"
#include "sim/render/texture_canvas.hpp"

namespace dynavins::sim {
namespace {

using V2 = Eigen::Vector2d;
constexpr double kPi = 3.141592653589793;

float fclamp(double v, double lo = 0.03, double hi = 0.76) {
  return static_cast<float>(std::clamp(v, lo, hi));
}

// A contrasting gray: far enough from `base` that a mark on it is a clear feature.
float contrasting(Rng& rng, float base) {
  const float up = base < 0.4f ? rng.uniform(0.5, 0.74) : rng.uniform(0.05, 0.22);
  return rng.chance(0.8) ? up : fclamp(base + rng.uniform(-0.25, 0.25));
}

// One glyph-like mark: a few bars, diagonals or a ring inside the box (x, y, w, h).
void paint_glyph(TextureCanvas& c, Rng& rng, double x, double y, double w, double h, double s, float v) {
  const int n = rng.uniform_int(2, 4);
  for (int i = 0; i < n; ++i) {
    switch (rng.uniform_int(0, 7)) {
      case 0: c.fill_rect(x, y, x + s, y + h, v); break;
      case 1: c.fill_rect(x + w - s, y, x + w, y + h, v); break;
      case 2: c.fill_rect(x + 0.5 * (w - s), y, x + 0.5 * (w + s), y + h, v); break;
      case 3: c.fill_rect(x, y + h - s, x + w, y + h, v); break;
      case 4: c.fill_rect(x, y + 0.5 * (h - s), x + w, y + 0.5 * (h + s), v); break;
      case 5: c.fill_rect(x, y, x + w, y + s, v); break;
      case 6: c.stroke({V2(x + 0.5 * s, y), V2(x + w - 0.5 * s, y + h)}, s, v); break;
      default: {
        std::vector<V2> ring;
        for (int k = 0; k <= 16; ++k) {
          const double th = 2.0 * kPi * k / 16;
          ring.emplace_back(x + 0.5 * w + 0.5 * (w - s) * std::cos(th), y + 0.5 * h + 0.5 * (h - s) * std::sin(th));
        }
        c.stroke(ring, s, v);
      }
    }
  }
}

// A line of "words" of glyphs between x0 and x1, glyph height h, bottom at y.
void paint_text(TextureCanvas& c, Rng& rng, double x0, double x1, double y, double h, float v) {
  const double w = h * rng.uniform(0.5, 0.75);
  const double s = std::max(h * rng.uniform(0.12, 0.2), c.texel());
  double x = x0;
  while (x + w <= x1) {
    const int len = rng.uniform_int(2, 8);
    for (int k = 0; k < len && x + w <= x1; ++k) {
      // Glyphs vary a little in width and stroke, as letters of a real typeface do.
      const double gw = w * rng.uniform(0.7, 1.1);
      const double gh = h * rng.uniform(0.85, 1.1);
      paint_glyph(c, rng, x, y + h * rng.uniform(-0.08, 0.08), gw, gh, std::max(s * rng.uniform(0.7, 1.3), c.texel()), v);
      x += gw + w * rng.uniform(0.2, 0.4);
    }
    x += w * rng.uniform(0.8, 1.6);
  }
}

// A sign board with a border and one or two lines of text.
void paint_sign(TextureCanvas& c, Rng& rng, double x0, double y0, double x1, double y1) {
  const float bg = rng.chance(0.5) ? static_cast<float>(rng.uniform(0.05, 0.2)) : static_cast<float>(rng.uniform(0.55, 0.74));
  c.fill_rect(x0, y0, x1, y1, bg);
  const double h = y1 - y0;
  const float fg = bg < 0.4f ? static_cast<float>(rng.uniform(0.6, 0.74)) : static_cast<float>(rng.uniform(0.04, 0.2));
  c.stroke({V2(x0, y0), V2(x1, y0), V2(x1, y1), V2(x0, y1), V2(x0, y0)}, std::max(0.02, 0.04 * h), fg);
  const int lines = h > 0.6 && rng.chance(0.5) ? 2 : 1;
  const double th = h * (lines == 2 ? 0.3 : 0.55);
  for (int l = 0; l < lines; ++l) {
    const double y = y0 + h * (lines == 2 ? (l == 0 ? 0.55 : 0.12) : 0.22);
    paint_text(c, rng, x0 + 0.1 * h + rng.uniform(0.0, 0.3 * h), x1 - 0.1 * h, y, th, fg);
  }
  if (rng.chance(0.5)) {  // logo
    const double r = 0.3 * h;
    c.fill_ellipse(V2(x0 + 0.5 * h, y0 + 0.5 * h), r, r, 0.0, contrasting(rng, bg));
  }
}

// A poster / advertisement: frame, a few large shapes, a text line.
void paint_poster(TextureCanvas& c, Rng& rng, double x0, double y0, double w, double h) {
  const float bg = static_cast<float>(rng.uniform(0.1, 0.74));
  c.fill_rect(x0, y0, x0 + w, y0 + h, bg);
  const int n = rng.uniform_int(2, 6);
  for (int i = 0; i < n; ++i) {
    const V2 p(x0 + rng.uniform(0.1, 0.9) * w, y0 + rng.uniform(0.2, 0.9) * h);
    const double a = rng.uniform(0.08, 0.35) * std::min(w, h);
    const float v = contrasting(rng, bg);
    if (rng.chance(0.5)) {
      c.fill_ellipse(p, a, a * rng.uniform(0.5, 1.5), rng.uniform(0.0, kPi), v);
    } else {
      c.fill_rotated_rect(p, V2(a, a * rng.uniform(0.3, 1.2)), rng.uniform(-0.4, 0.4), v);
    }
  }
  paint_text(c, rng, x0 + 0.05 * w, x0 + 0.95 * w, y0 + 0.05 * h, std::min(0.12 * h, 0.3), contrasting(rng, bg));
}

// Spray-painted scribbles near the ground.
void paint_graffiti(TextureCanvas& c, Rng& rng, double x0, double y0, double w, double h) {
  const float v = static_cast<float>(rng.chance(0.5) ? rng.uniform(0.04, 0.15) : rng.uniform(0.6, 0.74));
  const int strokes = rng.uniform_int(3, 8);
  for (int s = 0; s < strokes; ++s) {
    std::vector<V2> pts;
    V2 p(x0 + rng.uniform(0.0, w), y0 + rng.uniform(0.0, h));
    double dir = rng.uniform(0.0, 2.0 * kPi);
    const int n = rng.uniform_int(4, 12);
    for (int k = 0; k < n; ++k) {
      pts.push_back(p);
      dir += rng.uniform(-1.2, 1.2);
      p += rng.uniform(0.1, 0.35) * V2(std::cos(dir), std::sin(dir));
      p.x() = std::clamp(p.x(), x0, x0 + w);
      p.y() = std::clamp(p.y(), y0, y0 + h);
    }
    c.stroke(pts, rng.uniform(0.03, 0.1), v, 0.9f);
  }
}

// One window: frame, glass with reflection, blinds or curtains, glazing bars, sill.
void paint_window(TextureCanvas& c, Rng& rng, double x0, double y0, double w, double h, float frame) {
  const double f = 0.06;
  c.fill_rect(x0 - f, y0 - f, x0 + w + f, y0 + h + f, frame);
  const float glass = static_cast<float>(rng.uniform(0.04, 0.28));
  c.fill_rect(x0, y0, x0 + w, y0 + h, glass);
  if (rng.chance(0.6)) {  // sky reflected as a slanted light band
    const double a = rng.uniform(-0.3, 1.0) * w, b = a + rng.uniform(0.15, 0.6) * w, sk = rng.uniform(0.2, 0.6) * w;
    std::vector<V2> band = {V2(x0 + std::clamp(a, 0.0, w), y0), V2(x0 + std::clamp(b, 0.0, w), y0),
                            V2(x0 + std::clamp(b + sk, 0.0, w), y0 + h), V2(x0 + std::clamp(a + sk, 0.0, w), y0 + h)};
    c.fill_polygon(band, static_cast<float>(rng.uniform(0.45, 0.7)), static_cast<float>(rng.uniform(0.2, 0.5)));
  }
  if (rng.chance(0.45)) {  // blind pulled down part of the way
    const double bh = rng.uniform(0.1, 0.75) * h;
    c.fill_rect(x0, y0 + h - bh, x0 + w, y0 + h, static_cast<float>(rng.uniform(0.4, 0.72)), 0.9f);
    c.fill_rect(x0, y0 + h - bh - 0.03, x0 + w, y0 + h - bh, static_cast<float>(rng.uniform(0.1, 0.3)));
  } else if (rng.chance(0.4)) {  // curtains at the sides
    const float cv = static_cast<float>(rng.uniform(0.3, 0.65));
    c.fill_rect(x0, y0, x0 + rng.uniform(0.12, 0.35) * w, y0 + h, cv, 0.85f);
    c.fill_rect(x0 + w - rng.uniform(0.12, 0.35) * w, y0, x0 + w, y0 + h, cv, 0.85f);
  }
  if (rng.chance(0.4)) {  // something inside: a lamp, a plant, a shelf
    const V2 p(x0 + rng.uniform(0.2, 0.8) * w, y0 + rng.uniform(0.1, 0.6) * h);
    c.fill_ellipse(p, rng.uniform(0.05, 0.2), rng.uniform(0.05, 0.25), 0.0, static_cast<float>(rng.uniform(0.05, 0.6)), 0.7f);
  }
  const double bar = 0.05;
  if (rng.chance(0.6)) c.fill_rect(x0 + 0.5 * (w - bar), y0, x0 + 0.5 * (w + bar), y0 + h, frame);
  if (rng.chance(0.5)) {
    const double t = rng.uniform(0.6, 0.75) * h;
    c.fill_rect(x0, y0 + t, x0 + w, y0 + t + bar, frame);
  }
  c.fill_rect(x0 - 0.1, y0 - 0.1, x0 + w + 0.1, y0 - 0.03, static_cast<float>(rng.uniform(0.55, 0.74)));
  c.fill_rect(x0 - 0.1, y0 - 0.16, x0 + w + 0.1, y0 - 0.1, 0.1f, 0.35f);  // sill shadow
}

// Shop front at street level: glass, a door, a sign above.
void paint_shop(TextureCanvas& c, Rng& rng, double x0, double x1, double gf) {
  const double w = x1 - x0;
  const float frame = static_cast<float>(rng.chance(0.5) ? rng.uniform(0.05, 0.15) : rng.uniform(0.55, 0.72));
  const double top = gf - rng.uniform(0.9, 1.3);
  c.fill_rect(x0 + 0.15, 0.0, x1 - 0.15, top, frame);
  const double door_w = rng.uniform(0.9, 1.3);
  const double door_x = x0 + 0.3 + rng.uniform(0.0, std::max(0.0, w - door_w - 0.6));
  // Display windows either side of the door.
  const double sill = rng.uniform(0.3, 0.6);
  for (const auto& [a, b] : {std::pair{x0 + 0.3, door_x - 0.1}, std::pair{door_x + door_w + 0.1, x1 - 0.3}}) {
    if (b - a < 0.5) continue;
    c.fill_rect(a, sill, b, top - 0.12, static_cast<float>(rng.uniform(0.04, 0.25)));
    const int items = rng.uniform_int(1, 6);
    for (int i = 0; i < items; ++i) {  // goods on display
      const double ix = rng.uniform(a, b), iw = rng.uniform(0.1, 0.5), ih = rng.uniform(0.15, 0.8);
      c.fill_rect(ix, sill, std::min(b, ix + iw), std::min(top - 0.15, sill + ih), static_cast<float>(rng.uniform(0.1, 0.74)));
    }
    if (rng.chance(0.7)) {
      const double a2 = rng.uniform(a, b);
      c.fill_polygon({V2(a2, sill), V2(std::min(b, a2 + 0.4), sill), V2(std::min(b, a2 + 0.9), top - 0.12),
                      V2(std::min(b, a2 + 0.5), top - 0.12)},
                     0.65f, 0.3f);
    }
    if (rng.chance(0.5)) {  // posters stuck on the glass
      paint_poster(c, rng, a + rng.uniform(0.0, std::max(0.0, b - a - 0.6)), sill + rng.uniform(0.2, 0.6), 0.5, 0.7);
    }
  }
  c.fill_rect(door_x, 0.0, door_x + door_w, top - 0.1, static_cast<float>(rng.uniform(0.05, 0.3)));
  c.fill_rect(door_x + 0.1, 0.15, door_x + door_w - 0.1, top - 0.25, static_cast<float>(rng.uniform(0.1, 0.5)));
  c.fill_rect(door_x + door_w - 0.22, 0.95, door_x + door_w - 0.14, 1.15, 0.7f);  // handle
  paint_sign(c, rng, x0 + 0.2, top + 0.15, x1 - 0.2, gf - 0.15);
  if (rng.chance(0.4)) {  // awning: a dark band with a scalloped lower edge
    std::vector<V2> aw = {V2(x0 + 0.1, top + 0.1), V2(x1 - 0.1, top + 0.1), V2(x1 - 0.1, top - 0.05)};
    for (double x = x1 - 0.1; x > x0 + 0.1; x -= 0.45) aw.emplace_back(x - 0.22, top - 0.22);
    aw.emplace_back(x0 + 0.1, top - 0.05);
    c.fill_polygon(aw, static_cast<float>(rng.uniform(0.08, 0.7)));
  }
}

// Weathering common to all built surfaces: stains, dirt, fine texture.
void weather(TextureCanvas& c, uint64_t key, float base) {
  c.add_blotches(mix64(key + 11), 0.8, 0.38, base * 0.75f, 0.45f);
  c.add_blotches(mix64(key + 12), 0.25, 0.5, base * 1.2f + 0.04f, 0.35f);
  c.add_blotches(mix64(key + 13), 0.06, 0.55, base * 0.7f, 0.4f);
  c.modulate_fractal_noise(mix64(key + 14), 2.0, 6, 0.07f);
  c.add_grain(mix64(key + 15), 0.035f);
}

void paint_facade(TextureCanvas& c, uint64_t key, bool windows) {
  Rng rng(key);
  const double W = c.width_m(), H = c.height_m();
  const int material = rng.uniform_int(0, 2);
  const float base = static_cast<float>(material == 0 ? rng.uniform(0.45, 0.66)
                                        : material == 1 ? rng.uniform(0.36, 0.52) : rng.uniform(0.2, 0.32));
  c.image().setTo(base);
  c.add_fractal_noise(mix64(key + 1), 4.0, 3, 0.05f);
  if (material == 1 || !windows) {  // concrete panels with irregular joints and tints
    double y = 0.0;
    while (y < H) {
      const double ph = rng.uniform(1.0, 3.2);
      double x = -rng.uniform(0.0, 2.0);
      while (x < W) {
        const double pw = rng.uniform(1.0, 3.0);
        c.fill_rect(x, y, x + pw, y + ph, fclamp(base + rng.uniform(-0.07, 0.07)), 0.6f);
        c.fill_rect(x, y, x + 0.015, y + ph, base * 0.55f);
        x += pw;
      }
      c.fill_rect(0.0, y, W, y + 0.015, base * 0.55f);
      y += ph;
    }
  }
  if (windows) {
    const double gf = H > 7.0 ? rng.uniform(3.6, 4.6) : std::min(H, 4.0);
    const double fh = rng.uniform(2.8, 3.4);
    const double ww = rng.uniform(0.9, 1.6);
    const double wh = std::min(rng.uniform(1.2, 1.8), fh - 0.9);
    const double sp = ww + rng.uniform(0.8, 2.2);
    const int ncol = std::max(1, static_cast<int>((W - 0.6) / sp));
    const double margin = 0.5 * (W - ncol * sp);
    const float frame = static_cast<float>(rng.chance(0.6) ? rng.uniform(0.6, 0.74) : rng.uniform(0.08, 0.2));
    for (double fy = gf; fy + fh <= H - 0.4; fy += fh) {
      c.fill_rect(0.0, fy - 0.02, W, fy + 0.1, fclamp(base * 1.2 + 0.05), 0.8f);  // cornice
      c.fill_rect(0.0, fy - 0.1, W, fy - 0.02, base * 0.5f, 0.5f);
      const double sill = fy + rng.uniform(0.8, 1.0);
      for (int i = 0; i < ncol; ++i) {
        const double x = margin + (i + 0.5) * sp - 0.5 * ww + rng.uniform(-0.03, 0.03);
        paint_window(c, rng, x, sill, ww, wh, frame);
        if (rng.chance(0.3)) {  // rain streak below the sill
          c.fill_ellipse(V2(x + rng.uniform(0.1, ww - 0.1), sill - 0.6), 0.05, 0.5, 0.0, base * 0.7f, 0.3f);
        }
        if (rng.chance(0.1)) {  // balcony railing / air conditioner
          c.fill_rect(x - 0.1, sill - 0.1, x + ww + 0.1, sill + 0.25, static_cast<float>(rng.uniform(0.1, 0.7)));
        }
      }
    }
    // Ground floor: shops of varied width, or plain doors and windows.
    double x = rng.uniform(0.0, 1.0);
    while (x < W - 2.5) {
      const double sw = std::min(rng.uniform(3.0, 8.0), W - x);
      if (rng.chance(0.75)) {
        paint_shop(c, rng, x, x + sw, gf);
      } else {
        paint_window(c, rng, x + 0.5, 0.9, std::min(1.4, sw - 1.0), std::min(1.6, gf - 1.6), frame);
        paint_poster(c, rng, x + sw - 1.2, 0.8, 0.8, 1.1);
      }
      x += sw + rng.uniform(0.3, 1.2);
    }
  } else {  // boundary wall
    const int posters = static_cast<int>(W / rng.uniform(3.0, 8.0));
    for (int i = 0; i < posters; ++i) {
      const double pw = rng.uniform(0.6, 2.5), ph = std::min(rng.uniform(0.8, 1.8), H - 0.4);
      paint_poster(c, rng, rng.uniform(0.0, std::max(0.1, W - pw)), rng.uniform(0.2, std::max(0.3, H - ph - 0.1)), pw, ph);
    }
    const int tags = static_cast<int>(W / rng.uniform(2.0, 6.0));
    for (int i = 0; i < tags; ++i) {
      paint_graffiti(c, rng, rng.uniform(0.0, W - 1.0), rng.uniform(0.1, 0.6), rng.uniform(0.8, 3.0), std::min(1.4, H - 0.7));
    }
    c.fill_rect(0.0, H - 0.15, W, H, fclamp(base * 1.25), 0.9f);  // coping
    c.fill_rect(0.0, 0.0, W, 0.25, base * 0.6f, 0.5f);          // splash zone
  }
  weather(c, key, base);
}

void paint_roof(TextureCanvas& c, uint64_t key) {
  Rng rng(key);
  const float base = static_cast<float>(rng.uniform(0.3, 0.5));
  c.image().setTo(base);
  c.add_fractal_noise(mix64(key + 1), 3.0, 5, 0.08f);
  c.add_blotches(mix64(key + 2), 0.05, 0.4, base * 0.6f, 0.6f);
  const int n = static_cast<int>(c.width_m() * c.height_m() / 30.0) + 1;
  for (int i = 0; i < n; ++i) {  // vents and skylights
    const V2 p(rng.uniform(0.0, c.width_m()), rng.uniform(0.0, c.height_m()));
    c.fill_rect(p.x(), p.y(), p.x() + rng.uniform(0.4, 2.0), p.y() + rng.uniform(0.4, 2.0), contrasting(rng, base));
  }
  c.add_grain(mix64(key + 3), 0.05f);
}

// Vehicle body colour: one per vehicle seed, from black to white.
float body_albedo(uint64_t seed) {
  static const float kColours[] = {0.1f, 0.14f, 0.22f, 0.35f, 0.45f, 0.58f, 0.68f, 0.72f};
  return kColours[mix64(seed ^ 0xC0102) % 8];
}

void paint_wheel(TextureCanvas& c, Rng& rng, const V2& p, double r) {
  c.fill_ellipse(p, r * 1.22, r * 1.22, 0.0, 0.04f);           // wheel arch shadow
  c.fill_ellipse(p, r, r, 0.0, 0.08f);                          // tyre
  const float rim = static_cast<float>(rng.uniform(0.35, 0.65));
  c.fill_ellipse(p, r * 0.62, r * 0.62, 0.0, rim);
  c.fill_ellipse(p, r * 0.5, r * 0.5, 0.0, rim * 0.5f);
  const int spokes = rng.uniform_int(4, 7);
  const double ph = rng.uniform(0.0, kPi);
  for (int k = 0; k < spokes; ++k) {
    const double a = ph + 2.0 * kPi * k / spokes;
    c.stroke({p + 0.12 * r * V2(std::cos(a), std::sin(a)), p + 0.52 * r * V2(std::cos(a), std::sin(a))}, 0.12 * r, rim);
  }
  c.fill_ellipse(p, r * 0.14, r * 0.14, 0.0, 0.15f);
}

// Glass: dark interior with seats and head rests, and the street reflected in it (a skyline of lighter
// bands, a slanted sky highlight), the common look of vehicle windows.
void paint_glass(TextureCanvas& c, Rng& rng, const std::vector<V2>& poly, float trim = -1.0f) {
  c.fill_polygon(poly, static_cast<float>(rng.uniform(0.05, 0.16)));
  double xa = 1e9, xb = -1e9, ya = 1e9, yb = -1e9;
  for (const auto& p : poly) {
    xa = std::min(xa, p.x()); xb = std::max(xb, p.x());
    ya = std::min(ya, p.y()); yb = std::max(yb, p.y());
  }
  const double w = xb - xa, h = yb - ya;
  // Clip helper: shapes are kept inside the window's bounding box (the frame is painted over later).
  auto inside = [&](V2 p) { return V2(std::clamp(p.x(), xa, xb), std::clamp(p.y(), ya, yb)); };
  const int items = rng.uniform_int(1, 4);
  for (int i = 0; i < items; ++i) {  // head rests, seat backs, a dashboard edge
    const V2 p(xa + rng.uniform(0.1, 0.9) * w, ya + rng.uniform(0.1, 0.6) * h);
    const double rx = std::min(0.5 * w, rng.uniform(0.06, 0.16)), ry = std::min(0.5 * h, rng.uniform(0.06, 0.2));
    c.fill_ellipse(p, rx, ry, 0.0, static_cast<float>(rng.uniform(0.02, 0.3)), 0.8f);
  }
  // Reflected skyline: building-like steps along the window.
  double x = xa;
  while (x < xb) {
    const double bw = rng.uniform(0.08, 0.4) * std::max(w, 0.5);
    const double top = ya + rng.uniform(0.15, 0.8) * h;
    c.fill_polygon({inside(V2(x, ya)), inside(V2(x + bw, ya)), inside(V2(x + bw, top)), inside(V2(x, top))},
                   static_cast<float>(rng.uniform(0.3, 0.6)), static_cast<float>(rng.uniform(0.08, 0.3)));
    x += bw;
  }
  const double a = xa + rng.uniform(-0.2, 0.8) * w, bw = rng.uniform(0.1, 0.4) * w, sk = rng.uniform(0.1, 0.5) * w;
  std::vector<V2> band = {V2(a, ya), V2(a + bw, ya), V2(a + bw + sk, yb), V2(a + sk, yb)};
  for (auto& p : band) p = inside(p);
  c.fill_polygon(band, static_cast<float>(rng.uniform(0.4, 0.7)), static_cast<float>(rng.uniform(0.15, 0.4)));
  if (rng.chance(0.4)) {  // a sticker or parking permit
    const V2 p(xa + rng.uniform(0.05, 0.8) * w, ya + rng.uniform(0.05, 0.7) * h);
    c.fill_rect(p.x(), p.y(), std::min(xb, p.x() + 0.08), std::min(yb, p.y() + 0.06), static_cast<float>(rng.uniform(0.4, 0.74)));
  }
  if (trim >= 0.0f) {  // chrome or rubber seal around the glass
    std::vector<V2> ring = poly;
    ring.push_back(poly.front());
    c.stroke(ring, 0.025, trim);
  }
}

// Window trim that stands out from the body: chrome on dark paint, black rubber on light paint.
float trim_for(float body) { return body < 0.3f ? 0.62f : 0.04f; }

void paint_plate(TextureCanvas& c, Rng& rng, double cx, double y, double w = 0.52, double h = 0.11) {
  c.fill_rect(cx - 0.5 * w, y, cx + 0.5 * w, y + h, 0.72f);
  c.fill_rect(cx - 0.5 * w, y, cx - 0.5 * w + 0.04, y + h, 0.2f);
  paint_text(c, rng, cx - 0.5 * w + 0.07, cx + 0.5 * w - 0.02, y + 0.2 * h, 0.6 * h, 0.06f);
}

// Radiator grille: bars of irregular spacing, thickness and length over a dark opening, a badge on top,
// so its corners do not repeat at a fixed pitch.
void paint_grille(TextureCanvas& c, Rng& rng, double x0, double y0, double x1, double y1, float bar) {
  c.fill_rect(x0, y0, x1, y1, 0.05f);
  const double h = y1 - y0, w = x1 - x0;
  // Each bar its own thickness and gap (at least a bar apart), so no two bar ends look alike.
  double y = y0 + rng.uniform(0.05, 0.15) * h;
  while (y < y1 - 0.04 * h) {
    const double t = rng.uniform(0.025, 0.1) * h;
    c.fill_rect(x0 + rng.uniform(0.0, 0.15) * w, y, x1 - rng.uniform(0.0, 0.15) * w, std::min(y1, y + t),
                fclamp(bar * rng.uniform(0.7, 1.15)));
    y += t + rng.uniform(0.12, 0.3) * h;
  }
  if (rng.chance(0.6)) c.fill_rect(x0 + 0.47 * w, y0, x0 + 0.53 * w, y1, bar * 0.8f);  // divider
  const V2 badge(x0 + rng.uniform(0.35, 0.65) * w, y0 + rng.uniform(0.3, 0.7) * h);
  c.fill_ellipse(badge, 0.07 * w + 0.03, 0.18 * h + 0.02, rng.uniform(-0.3, 0.3), 0.7f);
  c.fill_ellipse(badge, 0.04 * w + 0.015, 0.1 * h + 0.01, 0.0, 0.25f);
}

// Under a truck: frame rails, tanks, cross members, cables in the shadow.
void paint_chassis(TextureCanvas& c, Rng& rng, double x0, double x1, double y0, double y1) {
  c.fill_rect(x0, y0, x1, y1, 0.06f);
  const double h = y1 - y0;
  c.fill_rect(x0, y1 - 0.35 * h, x1, y1 - 0.15 * h, 0.2f);  // frame rail
  for (double x = x0 + rng.uniform(0.1, 0.5); x < x1 - 0.1; x += rng.uniform(0.25, 0.9)) {
    const double w = rng.uniform(0.05, 0.35);
    const float v = static_cast<float>(rng.uniform(0.1, 0.35));
    if (rng.chance(0.5)) {
      c.fill_rect(x, y0 + rng.uniform(0.1, 0.4) * h, std::min(x1, x + w), y1 - 0.15 * h, v);  // tank / box
    } else {
      c.stroke({V2(x, y0 + rng.uniform(0.1, 0.6) * h), V2(std::min(x1, x + w), y0 + rng.uniform(0.2, 0.8) * h)},
               0.02, v);  // hose / cable
    }
  }
}

void vehicle_finish(TextureCanvas& c, uint64_t key, float body) {
  // Sharp reflections of the surroundings: light on dark paint, darker on light paint.
  c.add_blotches(mix64(key + 20), 0.5, 0.45, body > 0.45f ? body - 0.2f : body + 0.2f, 0.4f);
  c.scale_blotches(mix64(key + 21), 0.3, 0.5, 0.7f, 0.5f);    // dirt, dents
  c.scale_blotches(mix64(key + 22), 0.05, 0.55, 1.35f, 0.5f); // scratches, specks
  c.modulate_fractal_noise(mix64(key + 23), 1.0, 5, 0.05f);
  c.add_grain(mix64(key + 24), 0.025f);
}

void paint_car_side(TextureCanvas& c, uint64_t seed, uint64_t key, bool front_at_u0) {
  Rng rng(key);
  const double L = c.width_m(), H = c.height_m();
  const float body = body_albedo(seed);
  auto X = [&](double d) { return front_at_u0 ? d : L - d; };  // distance from the front -> u
  c.image().setTo(body);
  c.fill_rect(0.0, 0.62 * H, L, 0.66 * H, fclamp(body * 1.3 + 0.08), 0.5f);  // shoulder highlight
  c.fill_rect(0.0, 0.0, L, 0.2 * H, fclamp(body * 0.55), 0.8f);              // sill / rocker
  // Side windows: slanted pillars front and rear, a B-pillar between.
  const double wy0 = 0.6 * H, wy1 = 0.9 * H;
  const double f0 = 0.24 * L, r0 = 0.86 * L, b = rng.uniform(0.5, 0.56) * L;
  paint_glass(c, rng, {V2(X(f0), wy0), V2(X(b - 0.05), wy0), V2(X(b - 0.05), wy1), V2(X(f0 + 0.35), wy1)}, trim_for(body));
  paint_glass(c, rng, {V2(X(b + 0.05), wy0), V2(X(r0), wy0), V2(X(r0 - 0.3), wy1), V2(X(b + 0.05), wy1)}, trim_for(body));
  // Door seams and handles.
  for (double d : {0.3 * L, b, 0.77 * L}) c.fill_rect(X(d) - 0.006, 0.15 * H, X(d) + 0.006, wy0, 0.03f);
  for (double d : {b - 0.12, 0.77 * L - 0.12}) c.fill_rect(X(d) - 0.1, 0.5 * H, X(d) + 0.1, 0.53 * H, 0.05f);
  c.fill_ellipse(V2(X(f0 + 0.05), wy0 + 0.02), 0.1, 0.06, 0.0, 0.06f);  // mirror
  // Character line: a crease catching the sky, lighter than the paint; door seams cross it.
  const double crease = rng.uniform(0.38, 0.5) * H;
  c.fill_rect(0.0, crease, L, crease + 0.025, fclamp(body + 0.18), 0.8f);
  c.fill_rect(0.0, crease - 0.02, L, crease, fclamp(body * 0.6), 0.8f);
  if (rng.chance(0.5)) c.fill_rect(X(0.12 * L), 0.24 * H, X(0.88 * L), 0.26 * H, trim_for(body));  // sill trim
  if (rng.chance(0.6)) c.fill_rect(X(0.18 * L) - 0.05, 0.5 * H, X(0.18 * L) + 0.05, 0.54 * H, fclamp(body + 0.3));  // side marker
  if (rng.chance(0.4)) c.fill_rect(X(0.83 * L) - 0.08, 0.55 * H, X(0.83 * L) + 0.08, 0.59 * H, 0.05f);  // fuel cap
  if (rng.chance(0.3)) paint_text(c, rng, X(0.35 * L), X(0.35 * L) + 1.0, 0.3 * H, 0.08, contrasting(rng, body));
  // Lights wrapping round the corners, a badge on the front wing, the bonnet shut line.
  c.fill_rect(std::min(X(0.0), X(0.14)), 0.52 * H, std::max(X(0.0), X(0.14)), 0.6 * H, 0.7f);
  c.fill_rect(std::min(X(L), X(L - 0.1)), 0.5 * H, std::max(X(L), X(L - 0.1)), 0.62 * H, 0.3f);
  c.fill_rect(std::min(X(L), X(L - 0.05)), 0.53 * H, std::max(X(L), X(L - 0.05)), 0.59 * H, 0.6f);
  c.fill_rect(X(0.09 * L) - 0.06, 0.64 * H, X(0.09 * L) + 0.06, 0.68 * H, fclamp(body + 0.35));
  c.fill_rect(X(0.2 * L) - 0.006, 0.45 * H, X(0.2 * L) + 0.006, 0.6 * H, 0.03f);
  c.fill_rect(std::min(X(0.0), X(0.2 * L)), 0.6 * H - 0.006, std::max(X(0.0), X(0.2 * L)), 0.6 * H + 0.006, 0.03f);
  paint_wheel(c, rng, V2(X(0.8), 0.31), 0.31);
  paint_wheel(c, rng, V2(X(L - 0.9), 0.31), 0.31);
  vehicle_finish(c, key, body);
}

void paint_car_end(TextureCanvas& c, uint64_t seed, uint64_t key, bool front) {
  Rng rng(key);
  const double W = c.width_m(), H = c.height_m();
  const float body = body_albedo(seed);
  c.image().setTo(body);
  c.fill_rect(0.0, 0.08 * H, W, 0.28 * H, fclamp(body * 0.6 + 0.03));  // bumper
  // Windscreen / rear window: a trapezoid in the upper part.
  paint_glass(c, rng, {V2(0.1 * W, 0.6 * H), V2(0.9 * W, 0.6 * H), V2(0.84 * W, 0.93 * H), V2(0.16 * W, 0.93 * H)},
              trim_for(body));
  if (front) {
    paint_grille(c, rng, 0.3 * W, 0.32 * H, 0.7 * W, 0.47 * H, fclamp(body * 0.8 + 0.2));
    for (double cx : {0.15 * W, 0.85 * W}) {
      c.fill_ellipse(V2(cx, 0.47 * H), 0.17, 0.07, 0.0, 0.1f);
      c.fill_ellipse(V2(cx, 0.47 * H), 0.13, 0.05, 0.0, 0.72f);
      c.fill_ellipse(V2(cx + 0.03, 0.47 * H), 0.04, 0.03, 0.0, 0.3f);
    }
    c.stroke({V2(0.25 * W, 0.62 * H), V2(0.5 * W, 0.65 * H)}, 0.02, 0.04f);  // wipers
    c.stroke({V2(0.55 * W, 0.62 * H), V2(0.8 * W, 0.65 * H)}, 0.02, 0.04f);
    paint_plate(c, rng, 0.5 * W, 0.14 * H);
  } else {
    for (double cx : {0.12 * W, 0.88 * W}) {
      c.fill_rect(cx - 0.14, 0.4 * H, cx + 0.14, 0.52 * H, 0.12f);
      c.fill_rect(cx - 0.11, 0.43 * H, cx + 0.11, 0.49 * H, 0.32f);
      c.fill_rect(cx - 0.05, 0.43 * H, cx + 0.02, 0.49 * H, 0.62f);
    }
    c.fill_rect(0.05 * W, 0.56 * H, 0.95 * W, 0.57 * H, 0.04f);  // lid seam
    c.fill_ellipse(V2(0.5 * W, 0.47 * H), 0.06, 0.04, 0.0, 0.7f);  // badge
    paint_text(c, rng, 0.62 * W, 0.8 * W, 0.36 * H, 0.04, 0.7f);
    paint_plate(c, rng, 0.5 * W, 0.3 * H);
    c.fill_rect(0.2 * W, 0.05 * H, 0.35 * W, 0.09 * H, 0.05f);  // exhaust
  }
  vehicle_finish(c, key, body);
}

void paint_car_top(TextureCanvas& c, uint64_t seed, uint64_t key) {
  Rng rng(key);
  const double L = c.width_m(), W = c.height_m();
  const float body = body_albedo(seed);
  c.image().setTo(body);
  // Seen from above, front at u = L: boot, rear window, roof, windscreen, bonnet.
  paint_glass(c, rng, {V2(0.64 * L, 0.1 * W), V2(0.78 * L, 0.08 * W), V2(0.78 * L, 0.92 * W), V2(0.64 * L, 0.9 * W)});
  paint_glass(c, rng, {V2(0.16 * L, 0.08 * W), V2(0.25 * L, 0.1 * W), V2(0.25 * L, 0.9 * W), V2(0.16 * L, 0.92 * W)});
  if (rng.chance(0.4)) paint_glass(c, rng, {V2(0.4 * L, 0.25 * W), V2(0.58 * L, 0.25 * W), V2(0.58 * L, 0.75 * W), V2(0.4 * L, 0.75 * W)});
  c.fill_rect(0.28 * L, 0.05 * W, 0.62 * L, 0.08 * W, 0.08f);  // roof rails
  c.fill_rect(0.28 * L, 0.92 * W, 0.62 * L, 0.95 * W, 0.08f);
  vehicle_finish(c, key, body);
}

void paint_truck_side(TextureCanvas& c, uint64_t seed, uint64_t key, bool front_at_u0) {
  Rng rng(key);
  const double L = c.width_m(), H = c.height_m();
  auto X = [&](double d) { return front_at_u0 ? d : L - d; };
  auto rect = [&](double d0, double y0, double d1, double y1, float v, float a = 1.0f) {
    c.fill_rect(std::min(X(d0), X(d1)), y0, std::max(X(d0), X(d1)), y1, v, a);
  };
  const float cab = body_albedo(seed);
  Rng box_rng(mix64(seed ^ 0xB0C5));  // same cargo colour on both sides
  const float box = static_cast<float>(box_rng.uniform(0.45, 0.74));
  const double cab_len = 2.3, floor_y = 1.05, cab_h = std::min(H, 3.0);
  paint_chassis(c, rng, 0.0, L, 0.0, floor_y);
  c.fill_rect(0.0, floor_y, L, H, 0.06f);  // gap behind the cab where nothing else is painted
  // Cab.
  rect(0.0, 0.4, cab_len, cab_h, cab);
  paint_glass(c, rng, {V2(X(0.25), cab_h - 1.05), V2(X(1.7), cab_h - 1.05), V2(X(1.7), cab_h - 0.15), V2(X(0.45), cab_h - 0.15)},
              trim_for(cab));
  rect(1.75, 0.6, 1.76, cab_h - 0.1, 0.04f);      // door seam
  rect(1.5, 1.7, 1.68, 1.74, 0.05f);              // handle
  rect(0.4, 0.3, 1.3, 0.45, 0.25f);               // steps
  rect(0.4, 0.55, 1.3, 0.7, 0.25f);
  c.fill_ellipse(V2(X(0.1), cab_h - 0.6), 0.08, 0.3, 0.0, 0.08f);  // mirror
  // Cargo box.
  rect(cab_len + 0.15, floor_y, L, H, box);
  rect(cab_len + 0.15, floor_y, L, floor_y + 0.08, fclamp(box * 0.6));  // bottom rail
  rect(cab_len + 0.15, H - 0.08, L, H, fclamp(box * 0.6));              // top rail
  for (double d = cab_len + 0.15 + box_rng.uniform(0.5, 1.2); d < L - 0.2; d += box_rng.uniform(0.9, 1.6)) {
    rect(d, floor_y, d + 0.05, H, fclamp(box * 0.82), 0.7f);  // posts, irregular spacing
  }
  // Advertising: big shapes, a logo, lines of lettering.
  const double a0 = cab_len + 0.6, a1 = L - 0.5;
  const int shapes = rng.uniform_int(3, 7);
  for (int i = 0; i < shapes; ++i) {
    const V2 p(X(rng.uniform(a0, a1)), rng.uniform(floor_y + 0.4, H - 0.4));
    const double s = rng.uniform(0.25, 0.9);
    const float v = contrasting(rng, box);
    if (rng.chance(0.4)) c.fill_ellipse(p, s, s * rng.uniform(0.6, 1.4), rng.uniform(0.0, kPi), v);
    else if (rng.chance(0.5)) c.fill_rotated_rect(p, V2(s * 1.5, s * 0.4), rng.uniform(-0.3, 0.3), v);
    else c.fill_polygon({p, p + V2(s, -s), p + V2(2 * s, 0.2 * s), p + V2(0.6 * s, 0.8 * s)}, v);
  }
  const float ink = contrasting(rng, box);
  paint_text(c, rng, std::min(X(a0), X(a1)), std::max(X(a0), X(a1)), floor_y + 1.2, rng.uniform(0.3, 0.55), ink);
  paint_text(c, rng, std::min(X(a0), X(a1)) + 0.5, std::max(X(a0), X(a1)) - 2.0, floor_y + 0.5, rng.uniform(0.12, 0.22), ink);
  // Chassis, tank, guard rail, wheels.
  rect(cab_len + 0.4, 0.5, cab_len + 1.4, 0.95, 0.5f);   // fuel tank
  rect(cab_len + 0.4, 0.5, cab_len + 1.4, 0.55, 0.2f);
  rect(cab_len + 1.6, 0.45, L - 3.6, 0.55, 0.45f);       // side guard
  for (double d : {1.2, L - 3.0, L - 1.8}) paint_wheel(c, rng, V2(X(d), 0.5), 0.5);
  vehicle_finish(c, key, box);
}

void paint_truck_front(TextureCanvas& c, uint64_t seed, uint64_t key) {
  Rng rng(key);
  const double W = c.width_m(), H = c.height_m();
  const float cab = body_albedo(seed);
  Rng box_rng(mix64(seed ^ 0xB0C5));
  const float box = static_cast<float>(box_rng.uniform(0.45, 0.74));
  const double cab_h = std::min(H, 3.0);
  c.image().setTo(box);  // the cargo box shows above the cab
  c.fill_rect(0.0, 0.4, W, cab_h, cab);
  paint_glass(c, rng, {V2(0.08 * W, cab_h - 1.1), V2(0.92 * W, cab_h - 1.1), V2(0.9 * W, cab_h - 0.12), V2(0.1 * W, cab_h - 0.12)},
              trim_for(cab));
  paint_grille(c, rng, 0.25 * W, 0.95, 0.75 * W, 1.75, fclamp(cab * 0.7 + 0.25));
  // Above the cab, the cargo box: marker lights and lettering.
  for (int i = rng.uniform_int(2, 5); i > 0; --i) {
    const double x = rng.uniform(0.05, 0.9) * W;
    c.fill_rect(x, H - 0.15, x + 0.08, H - 0.08, 0.72f);
  }
  if (H - cab_h > 0.3) paint_text(c, rng, 0.1 * W, 0.9 * W, cab_h + 0.1, 0.5 * (H - cab_h) - 0.05, contrasting(rng, box));
  paint_chassis(c, rng, 0.0, W, 0.0, 0.4);
  for (double cx : {0.3 * W, 0.7 * W}) c.fill_ellipse(V2(cx, 0.2), 0.07, 0.05, 0.0, 0.6f);  // fog lights
  paint_text(c, rng, 0.35 * W, 0.65 * W, 1.8, 0.1, fclamp(1.0 - cab));
  for (double cx : {0.12 * W, 0.88 * W}) {
    c.fill_rect(cx - 0.2, 0.75, cx + 0.2, 0.95, 0.1f);
    c.fill_rect(cx - 0.16, 0.78, cx + 0.16, 0.92, 0.72f);
  }
  c.fill_rect(0.0, 0.4, W, 0.72, 0.22f);  // bumper
  paint_plate(c, rng, 0.5 * W, 0.48);
  c.stroke({V2(0.2 * W, cab_h - 1.05), V2(0.48 * W, cab_h - 1.0)}, 0.025, 0.04f);
  c.stroke({V2(0.52 * W, cab_h - 1.05), V2(0.8 * W, cab_h - 1.0)}, 0.025, 0.04f);
  vehicle_finish(c, key, cab);
}

void paint_truck_back(TextureCanvas& c, uint64_t seed, uint64_t key) {
  Rng rng(key);
  const double W = c.width_m(), H = c.height_m();
  Rng box_rng(mix64(seed ^ 0xB0C5));
  const float box = static_cast<float>(box_rng.uniform(0.45, 0.74));
  const double floor_y = 1.05;
  paint_chassis(c, rng, 0.0, W, 0.0, floor_y);
  // Doors inside a metal frame.
  c.fill_rect(0.0, floor_y, W, H, 0.5f);
  c.fill_rect(0.08, floor_y + 0.08, W - 0.08, H - 0.12, box);
  c.fill_rect(0.5 * W - 0.01, floor_y + 0.08, 0.5 * W + 0.01, H - 0.12, 0.05f);
  // Lock bars with brackets at irregular heights, handles.
  for (double fx : {0.2, 0.36, 0.64, 0.8}) {
    const double x = fx * W;
    c.fill_rect(x - 0.022, floor_y + 0.1, x + 0.022, H - 0.14, 0.62f);
    c.fill_rect(x - 0.03, floor_y + 0.1, x - 0.022, H - 0.14, 0.15f);
    for (double y = floor_y + 0.2; y < H - 0.3; y += rng.uniform(0.6, 1.1)) c.fill_rect(x - 0.05, y, x + 0.05, y + 0.07, 0.3f);
    c.fill_rect(x - 0.015, floor_y + 0.55, x + 0.2 * (fx < 0.5 ? 1 : -1), floor_y + 0.6, 0.65f);
  }
  // Hinges along the outer edges.
  for (double y = floor_y + 0.3; y < H - 0.2; y += rng.uniform(0.55, 0.9)) {
    c.fill_rect(0.02, y, 0.2, y + 0.08, 0.18f);
    c.fill_rect(W - 0.2, y, W - 0.02, y + 0.08, 0.18f);
  }
  // Reflective tape of random segment lengths (not periodic).
  for (double x = 0.1; x < W - 0.1;) {
    const double seg = rng.uniform(0.12, 0.4);
    c.fill_rect(x, floor_y + 0.12, std::min(x + seg, W - 0.1), floor_y + 0.18, rng.chance(0.5) ? 0.72f : 0.2f);
    x += seg;
  }
  // Stickers: warning signs, a logo, a phone number.
  const int stickers = rng.uniform_int(2, 5);
  for (int i = 0; i < stickers; ++i) {
    const V2 p(rng.uniform(0.1, 0.9) * W, rng.uniform(floor_y + 0.5, H - 0.4));
    const double s = rng.uniform(0.08, 0.25);
    if (rng.chance(0.5)) c.fill_polygon({p + V2(-s, -0.8 * s), p + V2(s, -0.8 * s), p + V2(0, s)}, contrasting(rng, box));
    else c.fill_rect(p.x() - s, p.y() - 0.6 * s, p.x() + s, p.y() + 0.6 * s, contrasting(rng, box));
  }
  paint_text(c, rng, 0.1 * W, 0.45 * W, H - 0.6, 0.12, contrasting(rng, box));
  paint_text(c, rng, 0.55 * W, 0.9 * W, floor_y + 0.35, 0.09, contrasting(rng, box));
  // Under the box: lights, guard bar, plate, mud flaps.
  for (double cx : {0.1 * W, 0.9 * W}) {
    c.fill_rect(cx - 0.18, 0.7, cx + 0.18, 0.92, 0.12f);
    c.fill_rect(cx - 0.15, 0.73, cx, 0.89, 0.33f);
    c.fill_rect(cx, 0.73, cx + 0.15, 0.89, 0.64f);
    c.fill_rect(cx - 0.2, 0.05, cx + 0.2, 0.6, 0.09f);
  }
  c.fill_rect(0.05 * W, 0.42, 0.95 * W, 0.56, 0.55f);
  c.fill_rect(0.05 * W, 0.42, 0.95 * W, 0.45, 0.2f);
  paint_plate(c, rng, 0.5 * W, 0.7);
  vehicle_finish(c, key, box);
}

void paint_truck_top(TextureCanvas& c, uint64_t seed, uint64_t key) {
  Rng rng(key);
  const double L = c.width_m(), W = c.height_m();
  Rng box_rng(mix64(seed ^ 0xB0C5));
  const float box = static_cast<float>(box_rng.uniform(0.45, 0.74));
  c.image().setTo(box);
  for (double x = rng.uniform(0.3, 1.0); x < L; x += rng.uniform(0.8, 1.5)) c.fill_rect(x, 0.0, x + 0.04, W, fclamp(box * 0.8));
  c.fill_rect(L - 2.3, 0.0, L, W, body_albedo(seed));  // cab roof at the front end (u = L)
  vehicle_finish(c, key, box);
}

}  // namespace

cv::Mat paint_surface(const SurfaceSpec& spec) {
  double texel = spec.texel_m;
  const double longest = std::max(spec.width_m, spec.height_m);
  if (longest / texel > 8192.0) texel = longest / 8192.0;  // cap memory for very large faces
  const int cols = std::max(1, static_cast<int>(std::lround(spec.width_m / texel)));
  const int rows = std::max(1, static_cast<int>(std::lround(spec.height_m / texel)));
  TextureCanvas c(cols, rows, texel);
  const uint64_t key = hash3(spec.seed, static_cast<int64_t>(spec.kind), 0x7E47);
  switch (spec.kind) {
    case SurfaceKind::Facade: paint_facade(c, key, true); break;
    case SurfaceKind::Wall: paint_facade(c, key, false); break;
    case SurfaceKind::Roof: paint_roof(c, key); break;
    case SurfaceKind::CarSide: paint_car_side(c, spec.seed, key, spec.front_at_u0); break;
    case SurfaceKind::CarFront: paint_car_end(c, spec.seed, key, true); break;
    case SurfaceKind::CarBack: paint_car_end(c, spec.seed, key, false); break;
    case SurfaceKind::CarTop: paint_car_top(c, spec.seed, key); break;
    case SurfaceKind::TruckSide: paint_truck_side(c, spec.seed, key, spec.front_at_u0); break;
    case SurfaceKind::TruckFront: paint_truck_front(c, spec.seed, key); break;
    case SurfaceKind::TruckBack: paint_truck_back(c, spec.seed, key); break;
    case SurfaceKind::TruckTop: paint_truck_top(c, spec.seed, key); break;
  }
  return c.to_u8();
}

std::shared_ptr<const MipTexture> make_surface_texture(const SurfaceSpec& spec) {
  return std::make_shared<const MipTexture>(paint_surface(spec));
}

}  // namespace dynavins::sim
