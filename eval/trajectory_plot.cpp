#include "eval/trajectory_plot.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

namespace dynavins::eval {

namespace {

const cv::Scalar kBackground(255, 255, 255);
const cv::Scalar kGrid(228, 228, 228);
const cv::Scalar kFrame(90, 90, 90);
const cv::Scalar kText(30, 30, 30);
const cv::Scalar kGtColor(110, 110, 110);  // grey reference, like evo
const cv::Scalar kEstColor(180, 119, 31);  // matplotlib's default blue (BGR)
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kShift = 4;  // sub-pixel drawing: coordinates carry 4 fractional bits

// Smallest of 1, 2, 5 x 10^k that is >= raw, so grid labels stay round numbers.
double nice_step(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10.0 * p;
}

std::string metres_label(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::fabs(v) < 0.5 * step * 1e-6) v = 0.0;  // no "-0.0"
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// Metric x-y to image pixels with equal scale on both axes and y pointing up.
struct Mapping {
  double scale = 1.0;  // pixels per metre
  double cx = 0.0, cy = 0.0;
  cv::Rect area;
  cv::Point2d to_px(double x, double y) const {
    return {area.x + 0.5 * area.width + (x - cx) * scale, area.y + 0.5 * area.height - (y - cy) * scale};
  }
  cv::Point fixed(const cv::Point2d& p) const {
    return {static_cast<int>(std::lround(p.x * (1 << kShift))), static_cast<int>(std::lround(p.y * (1 << kShift)))};
  }
  double x_at(double px) const { return cx + (px - area.x - 0.5 * area.width) / scale; }
  double y_at(double py) const { return cy - (py - area.y - 0.5 * area.height) / scale; }
};

void draw_path(cv::Mat& img, const Mapping& m, const std::vector<Eigen::Vector3d>& path, const cv::Scalar& color) {
  if (path.empty()) return;
  std::vector<cv::Point> pts;
  pts.reserve(path.size());
  for (const Eigen::Vector3d& p : path) {
    const cv::Point q = m.fixed(m.to_px(p.x(), p.y()));
    if (pts.empty() || q != pts.back()) pts.push_back(q);  // dense 200 Hz input: drop repeats
  }
  cv::polylines(img, pts, false, color, 2, cv::LINE_AA, kShift);
}

void draw_start_end(cv::Mat& img, const Mapping& m, const std::vector<Eigen::Vector3d>& path,
                    const cv::Scalar& color) {
  if (path.empty()) return;
  const cv::Point2d s = m.to_px(path.front().x(), path.front().y());
  const cv::Point2d e = m.to_px(path.back().x(), path.back().y());
  // White halos keep the markers visible on top of the dense paths.
  cv::circle(img, m.fixed(s), 9 << kShift, kBackground, cv::FILLED, cv::LINE_AA, kShift);
  cv::circle(img, m.fixed(s), 7 << kShift, color, cv::FILLED, cv::LINE_AA, kShift);
  cv::circle(img, m.fixed(s), 7 << kShift, kText, 1, cv::LINE_AA, kShift);
  const cv::Point ep(static_cast<int>(std::lround(e.x)), static_cast<int>(std::lround(e.y)));
  cv::drawMarker(img, ep, kBackground, cv::MARKER_TILTED_CROSS, 20, 7, cv::LINE_AA);
  cv::drawMarker(img, ep, color, cv::MARKER_TILTED_CROSS, 18, 3, cv::LINE_AA);
}

void put_text(cv::Mat& img, const std::string& s, cv::Point org, double scale, int thickness = 1) {
  cv::putText(img, s, org, kFont, scale, kText, thickness, cv::LINE_AA);
}

cv::Size text_size(const std::string& s, double scale, int thickness = 1) {
  int base = 0;
  return cv::getTextSize(s, kFont, scale, thickness, &base);
}

void draw_legend(cv::Mat& img, const Mapping& m, const std::vector<Eigen::Vector3d>& gt,
                 const std::vector<Eigen::Vector3d>& est, const PlotOptions& o) {
  const double fs = 0.55;
  const int row = 26, sample = 36, pad = 10;
  const int text_w = std::max({text_size(o.gt_label, fs).width, text_size(o.est_label, fs).width,
                               text_size("start end", fs).width + 40});
  const cv::Size box(pad * 3 + sample + text_w, pad * 2 + row * 3);
  // Put the legend in the corner of the plot area that hides the fewest path points.
  const cv::Rect& a = m.area;
  const std::array<cv::Rect, 4> corners = {
      cv::Rect(a.x + a.width - box.width - 8, a.y + 8, box.width, box.height),
      cv::Rect(a.x + 8, a.y + 8, box.width, box.height),
      cv::Rect(a.x + a.width - box.width - 8, a.y + a.height - box.height - 8, box.width, box.height),
      cv::Rect(a.x + 8, a.y + a.height - box.height - 8, box.width, box.height)};
  cv::Rect best = corners[0];
  std::size_t best_hits = std::numeric_limits<std::size_t>::max();
  for (const cv::Rect& c : corners) {
    std::size_t hits = 0;
    for (const auto* path : {&gt, &est}) {
      for (const Eigen::Vector3d& p : *path) {
        const cv::Point2d q = m.to_px(p.x(), p.y());
        if (c.contains(cv::Point(static_cast<int>(q.x), static_cast<int>(q.y)))) ++hits;
      }
    }
    if (hits < best_hits) {
      best_hits = hits;
      best = c;
    }
  }
  cv::rectangle(img, best, kBackground, cv::FILLED);
  cv::rectangle(img, best, kFrame, 1);
  const int x0 = best.x + pad;
  int y = best.y + pad + row / 2;
  const auto line_entry = [&](const cv::Scalar& color, const std::string& label) {
    cv::line(img, {x0, y}, {x0 + sample, y}, color, 3, cv::LINE_AA);
    put_text(img, label, {x0 + sample + pad, y + 6}, fs);
    y += row;
  };
  line_entry(kGtColor, o.gt_label);
  line_entry(kEstColor, o.est_label);
  cv::circle(img, {x0 + sample / 2, y}, 6, kFrame, cv::FILLED, cv::LINE_AA);
  put_text(img, "start", {x0 + sample + pad, y + 6}, fs);
  const int end_x = x0 + sample + pad + text_size("start", fs).width + 14;
  cv::drawMarker(img, {end_x + 7, y}, kFrame, cv::MARKER_TILTED_CROSS, 14, 3, cv::LINE_AA);
  put_text(img, "end", {end_x + 20, y + 6}, fs);
}

}  // namespace

cv::Mat render_topdown_plot(const std::vector<Eigen::Vector3d>& gt, const std::vector<Eigen::Vector3d>& est,
                            const PlotOptions& o) {
  if (gt.empty() && est.empty()) throw std::invalid_argument("plot: both trajectories are empty");
  if (o.width < 400 || o.height < 300) throw std::invalid_argument("plot: image must be at least 400 x 300 pixels");

  cv::Mat img(o.height, o.width, CV_8UC3, kBackground);
  const int left = 80, right = 30, top = 56, bottom = 62;
  Mapping m;
  m.area = cv::Rect(left, top, o.width - left - right, o.height - top - bottom);

  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto* path : {&gt, &est}) {
    for (const Eigen::Vector3d& p : *path) {
      x0 = std::min(x0, p.x());
      x1 = std::max(x1, p.x());
      y0 = std::min(y0, p.y());
      y1 = std::max(y1, p.y());
    }
  }
  if (!std::isfinite(x0 + x1 + y0 + y1)) throw std::invalid_argument("plot: non-finite position");
  // 6 % margin around the data; at least 10 cm of view so a static trajectory still draws.
  const double view_x = 1.12 * (x1 - x0), view_y = 1.12 * (y1 - y0);
  m.scale = std::min(m.area.width / std::max(view_x, 1e-12), m.area.height / std::max(view_y, 1e-12));
  m.scale = std::min(m.scale, std::min(m.area.width, m.area.height) / 0.1);
  m.cx = 0.5 * (x0 + x1);
  m.cy = 0.5 * (y0 + y1);

  // Grid: round-valued lines about every 90 pixels, labelled in metres outside the plot area.
  const double step = nice_step(90.0 / m.scale);
  const double fs = 0.5;
  for (double gx = std::ceil(m.x_at(m.area.x) / step) * step; gx <= m.x_at(m.area.br().x); gx += step) {
    const int px = static_cast<int>(std::lround(m.to_px(gx, 0).x));
    cv::line(img, {px, m.area.y}, {px, m.area.br().y}, kGrid, 1);
    const std::string s = metres_label(gx, step);
    put_text(img, s, {px - text_size(s, fs).width / 2, m.area.br().y + 20}, fs);
  }
  for (double gy = std::ceil(m.y_at(m.area.br().y) / step) * step; gy <= m.y_at(m.area.y); gy += step) {
    const int py = static_cast<int>(std::lround(m.to_px(0, gy).y));
    cv::line(img, {m.area.x, py}, {m.area.br().x, py}, kGrid, 1);
    const std::string s = metres_label(gy, step);
    put_text(img, s, {m.area.x - 8 - text_size(s, fs).width, py + 5}, fs);
  }
  cv::rectangle(img, m.area, kFrame, 1);
  put_text(img, "x [m]", {m.area.x + m.area.width / 2 - text_size("x [m]", 0.6).width / 2, o.height - 14}, 0.6);
  put_text(img, "y [m]", {8, m.area.y - 10}, 0.6);

  // Paths are clipped to the plot area so nothing draws over the labels.
  cv::Mat inner = img(m.area);
  Mapping mi = m;
  mi.area = cv::Rect(0, 0, m.area.width, m.area.height);
  draw_path(inner, mi, gt, kGtColor);
  draw_path(inner, mi, est, kEstColor);
  draw_start_end(inner, mi, gt, kGtColor);
  draw_start_end(inner, mi, est, kEstColor);
  draw_legend(img, m, gt, est, o);

  if (!o.title.empty()) {
    double ts = 0.75;
    while (ts > 0.35 && text_size(o.title, ts, 2).width > o.width - 20) ts -= 0.05;
    put_text(img, o.title, {(o.width - text_size(o.title, ts, 2).width) / 2, 34}, ts, 2);
  }
  return img;
}

void write_topdown_plot(const std::string& png_path, const std::vector<Eigen::Vector3d>& gt,
                        const std::vector<Eigen::Vector3d>& est, const PlotOptions& options) {
  std::string ext = std::filesystem::path(png_path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".png") throw std::runtime_error(png_path + ": plot file name must end in .png");
  const cv::Mat img = render_topdown_plot(gt, est, options);
  bool ok = false;
  try {
    ok = cv::imwrite(png_path, img);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(png_path + ": cannot write plot: " + e.err);
  }
  if (!ok) throw std::runtime_error(png_path + ": cannot write plot (check the directory and the .png extension)");
}

}  // namespace dynavins::eval
