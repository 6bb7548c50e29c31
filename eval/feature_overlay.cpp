#include "eval/feature_overlay.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string_view>

namespace dynavins::eval {

namespace {

std::vector<std::string_view> split_csv(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

std::string trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return std::string(s);
}

}  // namespace

std::size_t FeatureFrame::rejected() const {
  return static_cast<std::size_t>(
      std::count_if(features.begin(), features.end(), [](const OverlayFeature& f) { return f.weight < kRejectWeight; }));
}

std::size_t FeatureFrame::moving() const {
  return static_cast<std::size_t>(
      std::count_if(features.begin(), features.end(), [](const OverlayFeature& f) { return f.sim_label > 0; }));
}

std::vector<FeatureFrame> read_feature_frames(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ":1: empty file, expected a features.csv header");
  // Columns by name, so added columns do not break old readers.
  const std::vector<std::string> wanted = {"t_ns", "seq", "u", "v", "weight", "sim_label"};
  std::map<std::string, std::size_t> col;
  {
    const auto names = split_csv(line);
    for (std::size_t i = 0; i < names.size(); ++i) col[trimmed(names[i])] = i;
    for (const std::string& w : wanted) {
      if (col.find(w) == col.end())
        throw std::runtime_error(path + ":1: header has no '" + w + "' column (expected dynavins run's features.csv)");
    }
  }
  const std::size_t need = std::max({col["t_ns"], col["seq"], col["u"], col["v"], col["weight"], col["sim_label"]}) + 1;

  std::vector<FeatureFrame> frames;
  std::size_t line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (trimmed(line).empty()) continue;
    const auto tok = split_csv(line);
    const std::string where = path + ":" + std::to_string(line_no);
    if (tok.size() < need)
      throw std::runtime_error(where + ": expected at least " + std::to_string(need) + " comma-separated fields, found " +
                               std::to_string(tok.size()));
    const auto integer = [&](const char* name) -> long long {
      const std::string s = trimmed(tok[col[name]]);
      char* end = nullptr;
      errno = 0;
      const long long x = std::strtoll(s.c_str(), &end, 10);
      if (s.empty() || *end != '\0' || errno == ERANGE)
        throw std::runtime_error(where + ": field '" + name + "' is not an integer: '" + s + "'");
      return x;
    };
    const auto real = [&](const char* name) -> double {
      const std::string s = trimmed(tok[col[name]]);
      char* end = nullptr;
      const double x = std::strtod(s.c_str(), &end);
      if (s.empty() || *end != '\0' || !std::isfinite(x))
        throw std::runtime_error(where + ": field '" + name + "' is not a finite number: '" + s + "'");
      return x;
    };
    const std::int64_t t_ns = integer("t_ns");
    const std::int64_t seq = integer("seq");
    OverlayFeature f;
    f.u = real("u");
    f.v = real("v");
    f.weight = real("weight");
    f.sim_label = static_cast<int>(integer("sim_label"));
    if (frames.empty() || frames.back().t_ns != t_ns) {
      if (!frames.empty() && t_ns < frames.back().t_ns)
        throw std::runtime_error(where + ": field 't_ns' goes back in time (" + std::to_string(t_ns) + " after " +
                                 std::to_string(frames.back().t_ns) + ")");
      frames.push_back({t_ns, seq, {}});
    }
    frames.back().features.push_back(f);
  }
  if (in.bad()) throw std::runtime_error(path + ": read error");
  return frames;
}

std::vector<std::size_t> pick_overlay_frames(const std::vector<FeatureFrame>& frames, std::size_t n, double min_gap_s) {
  std::vector<std::size_t> order(frames.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const std::size_t ma = frames[a].moving(), mb = frames[b].moving();
    if (ma != mb) return ma > mb;
    return frames[a].rejected() > frames[b].rejected();
  });
  const auto gap_ns = static_cast<std::int64_t>(min_gap_s * 1e9);
  std::vector<std::size_t> picked;
  for (std::size_t i : order) {
    if (picked.size() >= n) break;
    if (frames[i].features.empty()) continue;
    const bool close = std::any_of(picked.begin(), picked.end(), [&](std::size_t p) {
      return std::llabs(static_cast<long long>(frames[p].t_ns - frames[i].t_ns)) < gap_ns;
    });
    if (!close) picked.push_back(i);
  }
  std::sort(picked.begin(), picked.end(), [&](std::size_t a, std::size_t b) { return frames[a].t_ns < frames[b].t_ns; });
  return picked;
}

cv::Mat draw_feature_overlay(const cv::Mat& image, const std::vector<OverlayFeature>& features,
                             const std::string& caption_text, const OverlayStyle& style) {
  if (image.empty()) throw std::invalid_argument("overlay: empty image");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("overlay: expected an 8-bit gray or BGR image");
  cv::Mat bgr;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else bgr = image.clone();

  const int r = std::max(1, style.radius);
  // Kept features first so a rejected cross on top of a kept circle stays visible.
  for (int pass = 0; pass < 2; ++pass) {
    for (const OverlayFeature& f : features) {
      const bool kept = f.weight >= kRejectWeight;
      if (kept != (pass == 0)) continue;
      if (!(f.u >= 0.0 && f.v >= 0.0 && f.u < bgr.cols && f.v < bgr.rows)) continue;
      const cv::Point c(static_cast<int>(std::lround(f.u)), static_cast<int>(std::lround(f.v)));
      if (kept) {
        cv::circle(bgr, c, r, kKeptColor, style.thickness, cv::LINE_AA);
      } else {
        cv::line(bgr, c + cv::Point(-r, -r), c + cv::Point(r, r), kRejectedColor, style.thickness, cv::LINE_AA);
        cv::line(bgr, c + cv::Point(-r, r), c + cv::Point(r, -r), kRejectedColor, style.thickness, cv::LINE_AA);
      }
    }
  }
  if (!style.caption) return bgr;

  const int band = 30;
  cv::Mat out(bgr.rows + band, bgr.cols, CV_8UC3, cv::Scalar(32, 32, 32));
  bgr.copyTo(out(cv::Rect(0, 0, bgr.cols, bgr.rows)));
  double fs = 0.55;
  int base = 0;
  while (fs > 0.3 && cv::getTextSize(caption_text, cv::FONT_HERSHEY_SIMPLEX, fs, 1, &base).width > bgr.cols - 12) fs -= 0.05;
  cv::putText(out, caption_text, {6, bgr.rows + band - 10}, cv::FONT_HERSHEY_SIMPLEX, fs, cv::Scalar(240, 240, 240), 1,
              cv::LINE_AA);
  return out;
}

std::string overlay_caption(const FeatureFrame& frame, double seconds_from_start) {
  const std::size_t n = frame.features.size(), rej = frame.rejected();
  char buf[256];
  int len = std::snprintf(buf, sizeof buf, "t %.2f s | %zu features, %zu rejected (%.0f %%)", seconds_from_start, n, rej,
                          n ? 100.0 * static_cast<double>(rej) / static_cast<double>(n) : 0.0);
  const bool labelled = std::any_of(frame.features.begin(), frame.features.end(),
                                    [](const OverlayFeature& f) { return f.sim_label >= 0; });
  if (labelled && len > 0 && static_cast<std::size_t>(len) < sizeof buf) {
    std::size_t moving_rejected = 0;
    for (const OverlayFeature& f : frame.features) moving_rejected += (f.sim_label > 0 && f.weight < kRejectWeight);
    std::snprintf(buf + len, sizeof buf - static_cast<std::size_t>(len), " | %zu on moving objects, %zu of them rejected",
                  frame.moving(), moving_rejected);
  }
  return buf;
}

cv::Mat tile_images(const std::vector<cv::Mat>& images, int cols) {
  if (images.empty()) throw std::invalid_argument("tile: no images");
  if (cols < 1) throw std::invalid_argument("tile: need at least one column");
  const cv::Size size = images.front().size();
  const int type = images.front().type();
  for (const cv::Mat& m : images) {
    if (m.size() != size || m.type() != type) throw std::invalid_argument("tile: images differ in size or type");
  }
  const int n = static_cast<int>(images.size());
  const int c = std::min(cols, n), rows = (n + c - 1) / c;
  cv::Mat out(rows * size.height, c * size.width, type, cv::Scalar::all(0));
  for (int i = 0; i < n; ++i) {
    images[static_cast<std::size_t>(i)].copyTo(
        out(cv::Rect((i % c) * size.width, (i / c) * size.height, size.width, size.height)));
  }
  return out;
}

}  // namespace dynavins::eval
