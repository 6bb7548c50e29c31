#include "eval/comparison_plot.hpp"

#include "eval/png_output.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace dynavins::eval {

namespace {

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kGridLine(226, 226, 226);
const cv::Scalar kBorder(90, 90, 90);
const cv::Scalar kInk(30, 30, 30);
const cv::Scalar kTruth(120, 120, 120);
constexpr int kFace = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kBits = 4;  // fractional bits of sub-pixel drawing

struct Box {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -std::numeric_limits<double>::infinity();
  double y0 = std::numeric_limits<double>::infinity(), y1 = -std::numeric_limits<double>::infinity();
  bool valid() const { return x0 <= x1 && y0 <= y1; }
  void add(const Eigen::Vector3d& p) {
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y());
    y1 = std::max(y1, p.y());
  }
  bool contains(const Eigen::Vector3d& p) const { return p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1; }
};

// Grid spacing: the smallest 1, 2 or 5 x 10^k not below `raw`.
double round_step(double raw) {
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0}) {
    if (f * decade >= raw) return f * decade;
  }
  return 10.0 * decade;
}

std::string grid_label(double v, double step) {
  const int digits = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::fabs(v) < 1e-9 * step) v = 0.0;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

cv::Size measure(const std::string& s, double scale, int thickness = 1) {
  int baseline = 0;
  return cv::getTextSize(s, kFace, scale, thickness, &baseline);
}

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale, int thickness = 1) {
  cv::putText(img, s, at, kFace, scale, kInk, thickness, cv::LINE_AA);
}

// Metres to pixels: equal scale on both axes, y up, centred on (cx, cy) inside `area`.
struct View {
  cv::Rect area;
  double px_per_m = 1.0, cx = 0.0, cy = 0.0;
  cv::Point2d px(double x, double y) const {
    return {area.x + 0.5 * area.width + (x - cx) * px_per_m, area.y + 0.5 * area.height - (y - cy) * px_per_m};
  }
  cv::Point sub(const cv::Point2d& p) const {
    return {static_cast<int>(std::lround(p.x * (1 << kBits))), static_cast<int>(std::lround(p.y * (1 << kBits)))};
  }
  double metres_x(double px_x) const { return cx + (px_x - area.x - 0.5 * area.width) / px_per_m; }
  double metres_y(double px_y) const { return cy - (px_y - area.y - 0.5 * area.height) / px_per_m; }
};

void polyline(cv::Mat& img, const View& v, const std::vector<Eigen::Vector3d>& path, const cv::Scalar& color,
              int thickness) {
  if (path.empty()) return;
  // Far-away points would overflow the fixed-point coordinates: clamp them well outside the image.
  const double lim = 4.0 * std::max(img.cols, img.rows);
  std::vector<cv::Point> pts;
  pts.reserve(path.size());
  for (const Eigen::Vector3d& p : path) {
    cv::Point2d q = v.px(p.x(), p.y());
    q.x = std::clamp(q.x, -lim, lim);
    q.y = std::clamp(q.y, -lim, lim);
    const cv::Point s = v.sub(q);
    if (pts.empty() || s != pts.back()) pts.push_back(s);
  }
  cv::polylines(img, pts, false, color, thickness, cv::LINE_AA, kBits);
}

void markers(cv::Mat& img, const View& v, const std::vector<Eigen::Vector3d>& path, const cv::Scalar& color) {
  if (path.empty()) return;
  const cv::Rect inside(0, 0, img.cols, img.rows);
  const cv::Point2d s = v.px(path.front().x(), path.front().y());
  const cv::Point2d e = v.px(path.back().x(), path.back().y());
  const cv::Point si(static_cast<int>(std::lround(s.x)), static_cast<int>(std::lround(s.y)));
  const cv::Point ei(static_cast<int>(std::lround(e.x)), static_cast<int>(std::lround(e.y)));
  if (inside.contains(si)) {
    cv::circle(img, si, 8, kWhite, cv::FILLED, cv::LINE_AA);
    cv::circle(img, si, 6, color, cv::FILLED, cv::LINE_AA);
  }
  if (inside.contains(ei)) {
    cv::drawMarker(img, ei, kWhite, cv::MARKER_TILTED_CROSS, 20, 7, cv::LINE_AA);
    cv::drawMarker(img, ei, color, cv::MARKER_TILTED_CROSS, 18, 3, cv::LINE_AA);
  }
}

}  // namespace

cv::Scalar comparison_color(std::size_t i) {
  // Tableau-like colours in BGR: orange, blue, green, red, purple, brown, pink, olive.
  static const std::array<cv::Scalar, 8> kPalette = {
      cv::Scalar(14, 127, 255), cv::Scalar(180, 119, 31), cv::Scalar(44, 160, 44),   cv::Scalar(40, 39, 214),
      cv::Scalar(189, 103, 148), cv::Scalar(75, 86, 140), cv::Scalar(194, 119, 227), cv::Scalar(34, 189, 188)};
  return kPalette[i % kPalette.size()];
}

cv::Mat render_comparison_plot(const std::vector<Eigen::Vector3d>& gt, const std::vector<NamedPath>& estimates,
                               const ComparisonPlotOptions& o) {
  if (o.width < 400 || o.height < 300) throw std::invalid_argument("comparison plot: image must be at least 400 x 300");
  Box truth, all;
  for (const Eigen::Vector3d& p : gt) {
    if (!p.allFinite()) throw std::invalid_argument("comparison plot: non-finite ground-truth position");
    truth.add(p);
    all.add(p);
  }
  for (const NamedPath& e : estimates) {
    for (const Eigen::Vector3d& p : e.points) {
      if (!p.allFinite()) throw std::invalid_argument("comparison plot: non-finite position in '" + e.label + "'");
      all.add(p);
    }
  }
  if (!all.valid()) throw std::invalid_argument("comparison plot: every trajectory is empty");

  // The view: everything, but capped around the ground truth when an estimate ran far away.
  Box view = all;
  if (truth.valid()) {
    const double extent = std::max({truth.x1 - truth.x0, truth.y1 - truth.y0, 10.0});
    const double m = o.max_view_margin * extent;
    view.x0 = std::max(view.x0, truth.x0 - m);
    view.x1 = std::min(view.x1, truth.x1 + m);
    view.y0 = std::max(view.y0, truth.y0 - m);
    view.y1 = std::min(view.y1, truth.y1 + m);
  }

  cv::Mat img(o.height, o.width, CV_8UC3, kWhite);
  View v;
  v.area = cv::Rect(80, 56, o.width - 80 - 30, o.height - 56 - 62);
  const double span_x = 1.1 * (view.x1 - view.x0), span_y = 1.1 * (view.y1 - view.y0);
  v.px_per_m = std::min(v.area.width / std::max(span_x, 1e-9), v.area.height / std::max(span_y, 1e-9));
  v.px_per_m = std::min(v.px_per_m, std::min(v.area.width, v.area.height) / 0.1);  // at least 10 cm of view
  v.cx = 0.5 * (view.x0 + view.x1);
  v.cy = 0.5 * (view.y0 + view.y1);

  // Grid lines about every 90 px at round metre values, labelled outside the plot area.
  const double step = round_step(90.0 / v.px_per_m);
  for (double gx = std::ceil(v.metres_x(v.area.x) / step) * step; gx <= v.metres_x(v.area.br().x); gx += step) {
    const int x = static_cast<int>(std::lround(v.px(gx, 0).x));
    cv::line(img, {x, v.area.y}, {x, v.area.br().y}, kGridLine, 1);
    const std::string s = grid_label(gx, step);
    text(img, s, {x - measure(s, 0.5).width / 2, v.area.br().y + 20}, 0.5);
  }
  for (double gy = std::ceil(v.metres_y(v.area.br().y) / step) * step; gy <= v.metres_y(v.area.y); gy += step) {
    const int y = static_cast<int>(std::lround(v.px(0, gy).y));
    cv::line(img, {v.area.x, y}, {v.area.br().x, y}, kGridLine, 1);
    const std::string s = grid_label(gy, step);
    text(img, s, {v.area.x - 8 - measure(s, 0.5).width, y + 5}, 0.5);
  }
  cv::rectangle(img, v.area, kBorder, 1);
  text(img, "x [m]", {v.area.x + v.area.width / 2 - measure("x [m]", 0.6).width / 2, o.height - 14}, 0.6);
  text(img, "y [m]", {8, v.area.y - 10}, 0.6);

  // Paths drawn into the plot area only (a sub-image), ground truth first and thickest.
  cv::Mat inner = img(v.area);
  View vi = v;
  vi.area = cv::Rect(0, 0, v.area.width, v.area.height);
  polyline(inner, vi, gt, kTruth, 4);
  for (std::size_t i = 0; i < estimates.size(); ++i) polyline(inner, vi, estimates[i].points, comparison_color(i), 2);
  markers(inner, vi, gt, kTruth);
  for (std::size_t i = 0; i < estimates.size(); ++i) markers(inner, vi, estimates[i].points, comparison_color(i));

  // Legend, in the corner of the plot area that covers the fewest path points.
  std::vector<std::string> labels{o.gt_label};
  std::vector<cv::Scalar> colors{kTruth};
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    std::string label = estimates[i].label;
    const bool leaves = std::any_of(estimates[i].points.begin(), estimates[i].points.end(),
                                    [&](const Eigen::Vector3d& p) { return !view.contains(p); });
    if (leaves) label += " (leaves the view)";
    labels.push_back(label);
    colors.push_back(comparison_color(i));
  }
  const double fs = 0.55;
  const int row = 26, sample = 36, pad = 10;
  int text_w = measure("start   end", fs).width + 30;
  for (const std::string& s : labels) text_w = std::max(text_w, measure(s, fs).width);
  const cv::Size box(std::min(pad * 3 + sample + text_w, v.area.width - 16),
                     std::min(pad * 2 + row * static_cast<int>(labels.size() + 1), v.area.height - 16));
  const cv::Rect& a = v.area;
  const std::array<cv::Rect, 4> corners = {cv::Rect(a.br().x - box.width - 8, a.y + 8, box.width, box.height),
                                           cv::Rect(a.x + 8, a.y + 8, box.width, box.height),
                                           cv::Rect(a.br().x - box.width - 8, a.br().y - box.height - 8, box.width, box.height),
                                           cv::Rect(a.x + 8, a.br().y - box.height - 8, box.width, box.height)};
  cv::Rect legend = corners[0];
  std::size_t fewest = std::numeric_limits<std::size_t>::max();
  for (const cv::Rect& c : corners) {
    std::size_t hits = 0;
    const auto count = [&](const std::vector<Eigen::Vector3d>& path) {
      for (const Eigen::Vector3d& p : path) {
        const cv::Point2d q = v.px(p.x(), p.y());
        if (q.x >= c.x && q.x < c.br().x && q.y >= c.y && q.y < c.br().y) ++hits;
      }
    };
    count(gt);
    for (const NamedPath& e : estimates) count(e.points);
    if (hits < fewest) {
      fewest = hits;
      legend = c;
    }
  }
  cv::rectangle(img, legend, kWhite, cv::FILLED);
  cv::rectangle(img, legend, kBorder, 1);
  const int lx = legend.x + pad;
  int ly = legend.y + pad + row / 2;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    cv::line(img, {lx, ly}, {lx + sample, ly}, colors[i], i == 0 ? 4 : 3, cv::LINE_AA);
    text(img, labels[i], {lx + sample + pad, ly + 6}, fs);
    ly += row;
  }
  cv::circle(img, {lx + sample / 2, ly}, 6, kBorder, cv::FILLED, cv::LINE_AA);
  text(img, "start", {lx + sample + pad, ly + 6}, fs);
  const int ex = lx + sample + pad + measure("start", fs).width + 14;
  cv::drawMarker(img, {ex + 7, ly}, kBorder, cv::MARKER_TILTED_CROSS, 14, 3, cv::LINE_AA);
  text(img, "end", {ex + 20, ly + 6}, fs);

  if (!o.title.empty()) {
    double ts = 0.75;
    while (ts > 0.35 && measure(o.title, ts, 2).width > o.width - 20) ts -= 0.05;
    text(img, o.title, {(o.width - measure(o.title, ts, 2).width) / 2, 34}, ts, 2);
  }
  return img;
}

void write_comparison_plot(const std::string& png_path, const std::vector<Eigen::Vector3d>& gt,
                           const std::vector<NamedPath>& estimates, const ComparisonPlotOptions& options) {
  write_png_atomically(png_path, render_comparison_plot(gt, estimates, options));
}

}  // namespace dynavins::eval
