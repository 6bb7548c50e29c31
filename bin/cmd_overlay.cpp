// `dynavins overlay (--log FILE | --euroc DIR | --rosbag FILE) --features FEATURES.csv --out OUT.png
//  [--time S | --frames N] [--scale F]`: a run's weighted features drawn on the left images of its
// recording, like Fig. 1 of the paper (green circle: weight >= 0.5, red cross: rejected).
#include "bin/commands.hpp"
#include "bin/sensor_input.hpp"
#include "eval/feature_overlay.hpp"
#include "eval/png_output.hpp"

#include <CLI/CLI.hpp>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <variant>
#include <vector>

namespace dynavins::cli {

namespace {

namespace fs = std::filesystem;

struct OverlayArgs {
  SensorInput input;
  std::string features;
  std::string out;
  double time = NAN;
  std::size_t frames = 1;
  double scale = 1.0;
  double min_gap = 2.0;
  double td = 0.0;  ///< the run's config td: its features.csv times are the recording's + td
};

// The feature frame nearest to t_ns.
std::size_t nearest_frame(const std::vector<eval::FeatureFrame>& frames, std::int64_t t_ns) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    if (std::llabs(static_cast<long long>(frames[i].t_ns - t_ns)) <
        std::llabs(static_cast<long long>(frames[best].t_ns - t_ns)))
      best = i;
  }
  return best;
}

void run_overlay(const OverlayArgs& a) {
  std::string ext = fs::path(a.out).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw CommandError("overlay: --out " + a.out + ": the file name must end in .png", 2);
  const bool by_time = std::isfinite(a.time);
  if (by_time && a.time < 0) throw CommandError("overlay: --time must be >= 0 seconds from the start", 2);

  std::vector<eval::FeatureFrame> frames;
  try {
    frames = eval::read_feature_frames(a.features);
  } catch (const std::exception& e) {
    throw CommandError(std::string("overlay: ") + e.what(), 1);
  }
  if (frames.empty()) throw CommandError("overlay: " + a.features + ": no feature rows (did the run track?)", 1);

  // Which feature frames to show; with --time this waits for the recording's first frame.
  std::vector<std::size_t> chosen;
  if (!by_time) {
    chosen = eval::pick_overlay_frames(frames, a.frames, a.min_gap);
    if (chosen.empty()) throw CommandError("overlay: " + a.features + ": no frame with features", 1);
  }

  const std::int64_t td_ns = std::llround(a.td * 1e9);
  auto source = a.input.open();
  std::map<std::int64_t, cv::Mat> drawn;  // by t_ns
  std::int64_t t0 = 0;
  bool started = false;
  SensorEvent ev;
  try {
    while (source->next(ev)) {
      auto* frame = std::get_if<StereoFrame>(&ev);
      if (frame == nullptr) continue;
      frame->t_ns += td_ns;  // into the IMU clock, as `run` did (config key td)
      if (!started) {
        started = true;
        t0 = frame->t_ns;
        if (by_time) {
          const std::size_t i = nearest_frame(frames, t0 + static_cast<std::int64_t>(std::llround(a.time * 1e9)));
          chosen = {i};
          spdlog::info("overlay: --time {:.3f} s -> the estimated frame at {:.3f} s", a.time,
                       static_cast<double>(frames[i].t_ns - t0) * 1e-9);
        }
      }
      for (std::size_t i : chosen) {
        if (frames[i].t_ns != frame->t_ns) continue;
        const double t = static_cast<double>(frame->t_ns - t0) * 1e-9;
        const std::string caption = eval::overlay_caption(frames[i], t);
        spdlog::info("overlay: {}", caption);
        drawn[frame->t_ns] = eval::draw_feature_overlay(frame->left, frames[i].features, caption);
      }
      if (drawn.size() == chosen.size()) break;
    }
  } catch (const CommandError&) {
    throw;
  } catch (const std::exception& e) {
    throw CommandError(std::string("overlay: ") + e.what(), 1);
  }
  if (!started) throw CommandError("overlay: " + source->describe() + ": no camera frames", 1);
  for (std::size_t i : chosen) {
    if (drawn.count(frames[i].t_ns) == 0)
      throw CommandError("overlay: " + a.features + ": its frame at t_ns " + std::to_string(frames[i].t_ns) +
                             " is not in " + source->describe() +
                             (a.td == 0.0 ? " (features of another recording, or of a run whose config has a td: pass --td?)"
                                          : " with --td " + std::to_string(a.td) + " (features of another recording?)"),
                         1);
  }

  std::vector<cv::Mat> tiles;
  for (const auto& [t, img] : drawn) tiles.push_back(img);
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(tiles.size()))));
  cv::Mat out;
  try {
    out = eval::tile_images(tiles, cols);
    if (a.scale != 1.0) cv::resize(out, out, cv::Size(), a.scale, a.scale, cv::INTER_AREA);
    eval::write_png_atomically(a.out, out);
  } catch (const std::exception& e) {
    throw CommandError(std::string("overlay: ") + e.what(), 1);
  }
  std::printf("overlay     %zu frame(s) -> %s (%dx%d)\n", tiles.size(), a.out.c_str(), out.cols, out.rows);
}

}  // namespace

void add_overlay_command(CLI::App& app) {
  auto args = std::make_shared<OverlayArgs>();
  CLI::App* sub = app.add_subcommand(
      "overlay", "A run's weighted features on its left images (green: kept, red cross: rejected), as a PNG");
  args->input.add_options(*sub, /*with_log=*/true);
  sub->add_option("--features", args->features, "features.csv written by `dynavins run`")->required();
  sub->add_option("--out", args->out, "PNG to write")->required();
  auto* time = sub->add_option("--time", args->time, "show the estimated frame nearest to this many seconds from the start");
  auto* frames = sub->add_option("--frames", args->frames,
                                 "show the N frames with the most features on moving objects (else most rejected), "
                                 "at least --min-gap apart, in a grid")
                     ->check(CLI::Range(std::size_t{1}, std::size_t{16}))
                     ->capture_default_str();
  time->excludes(frames);
  sub->add_option("--min-gap", args->min_gap, "minimum time between frames picked by --frames [s]")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  sub->add_option("--td", args->td, "the run's config td [s] (image clock + td = IMU clock; features.csv is in the IMU clock)")
      ->check(CLI::Range(-1.0, 1.0))
      ->capture_default_str();
  sub->add_option("--scale", args->scale, "resize the picture by this factor")
      ->check(CLI::Range(0.05, 4.0))
      ->capture_default_str();
  sub->callback([args] { run_overlay(*args); });
}

}  // namespace dynavins::cli
