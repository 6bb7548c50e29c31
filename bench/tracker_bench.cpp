// Milliseconds per stereo frame of StereoTracker (150 features, 752x480) on one core: a generated
// street scene and the shared EuRoC V1_01 clip. Prints mean / p95 and the tracking statistics.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "io/euroc_dataset.hpp"
#include "sim/scenario/scenario.hpp"
#include "stages/tracker/kalibr_camera.hpp"
#include "stages/tracker/stereo_tracker.hpp"

using namespace dynavins;
namespace fs = std::filesystem;

namespace {

struct Times {
  std::vector<double> wall, cpu;
};

std::pair<double, double> mean_p95(std::vector<double> ms) {
  const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size());
  std::sort(ms.begin(), ms.end());
  return {mean, ms[std::min(ms.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(ms.size())))]};
}

void report(const char* name, const Times& t, const std::vector<TrackedFrame>& out) {
  if (t.wall.empty()) return;
  const auto [mean, p95] = mean_p95(t.wall);
  const auto [cmean, cp95] = mean_p95(t.cpu);
  double feats = 0, stereo = 0, len = 0;
  for (const auto& f : out) {
    feats += static_cast<double>(f.features.size());
    stereo += f.stats.stereo;
    for (const auto& t : f.features) len += t.track_length;
  }
  std::printf("%-15s frames %3zu  ms/frame wall mean %.2f p95 %.2f, thread cpu mean %.2f p95 %.2f  features/frame %.1f  stereo rate %.2f  mean track length %.1f\n",
              name, out.size(), mean, p95, cmean, cp95, feats / static_cast<double>(out.size()), stereo / std::max(1.0, feats),
              len / std::max(1.0, feats));
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

/// Wall time, and this thread's CPU time: the machine is shared, so wall time includes waiting.
template <typename F>
void time_ms(Times* t, F&& f) {
  const double c0 = thread_cpu_ms();
  const auto t0 = std::chrono::steady_clock::now();
  f();
  t->wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  t->cpu.push_back(thread_cpu_ms() - c0);
}

}  // namespace

/// The tracker with VINS-Fusion's EuRoC settings (150 features, 30 px apart, flow back on) and the two
/// optional steps it leaves off, each measured on its own: fundamental-matrix RANSAC and CLAHE; and
/// without our first-patch refinement (plain VINS-Fusion KLT), to show what it costs.
struct Variant {
  const char* name;
  tracker::TrackerOptions options;
};
std::vector<Variant> variants() {
  tracker::TrackerOptions base, ransac, clahe, plain;
  ransac.f_ransac = true;
  clahe.clahe = true;
  plain.patch_refine = false;
  return {{"", base}, {"+fransac", ransac}, {"+clahe", clahe}, {"-patch", plain}};
}

struct Args {
  bool sim = true, euroc = true;
  std::vector<std::string> variants;  ///< names as printed after the data set ("base" for none); empty: all
  int repeat = 1;
};

bool selected(const Args& a, const Variant& v) {
  const std::string name = *v.name ? v.name : "base";
  return a.variants.empty() || std::find(a.variants.begin(), a.variants.end(), name) != a.variants.end();
}

void run_variants(const Args& args, const char* data, const std::vector<StereoFrame>& frames, const CameraModelPtr& c0,
                  const CameraModelPtr& c1) {
  // Repeats run the variants in turn, so a load change on the shared machine hits them all alike.
  for (int r = 0; r < args.repeat; ++r)
    for (const Variant& v : variants()) {
      if (!selected(args, v)) continue;
      tracker::StereoTracker tracker(v.options, c0, c1);
      Times ms;
      std::vector<TrackedFrame> out;
      for (const auto& f : frames) time_ms(&ms, [&] { out.push_back(tracker.process(f)); });
      const std::string name = std::string(data) + v.name;
      report(name.c_str(), ms, out);
      long rejected = 0;
      for (const auto& f : out) rejected += f.stats.lost_ransac;
      if (v.options.f_ransac)
        std::printf("         F-RANSAC rejected %.2f tracks per frame\n", double(rejected) / out.size());
    }
}

const char* kUsage =
    "usage: bench_tracker [--data sim|euroc|all] [--variants base,+fransac,+clahe,-patch] [--repeat N]\n"
    "  --data      which frames to track (default all)\n"
    "  --variants  comma-separated tracker variants to time (default all; base = VINS-Fusion settings)\n"
    "  --repeat    runs of each variant, interleaved (default 1)\n";

[[noreturn]] void usage(int code) {
  std::fputs(kUsage, code == 0 ? stdout : stderr);
  std::exit(code);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (k == "--help" || k == "-h") usage(0);
    if (i + 1 >= argc) usage(2);
    const std::string value = argv[++i];
    if (k == "--data") {
      a.sim = value == "sim" || value == "all";
      a.euroc = value == "euroc" || value == "all";
      if (!a.sim && !a.euroc) usage(2);
    } else if (k == "--variants") {
      std::stringstream ss(value);
      for (std::string v; std::getline(ss, v, ',');) a.variants.push_back(v);
    } else if (k == "--repeat") {
      a.repeat = std::atoi(value.c_str());
      if (a.repeat < 1) usage(2);
    } else {
      usage(2);
    }
  }
  return a;
}

int main(int argc, char** argv) {
  const Args args = parse(argc, argv);
  cv::setNumThreads(1);  // the goal is per core; the pipeline runs other stages on the other cores

  if (args.sim) {  // Generated scene: frames rendered first so only the tracker is timed.
    const fs::path path = fs::temp_directory_path() / "dynavins_bench_tracker.yaml";
    std::ofstream(path) << "%YAML:1.0\n---\nname: bench\nseed: 3\nduration: 5\n"
                           "world: { x_min: -10, x_max: 40 }\n"
                           "motion: { profile: drone, waypoints: [0, -1.5, 1.6, 20, -1.5, 1.6] }\n"
                           "objects:\n  - { kind: truck, motion: cross_ahead, t: 2.5, distance: 7, speed: 6 }\n";
    sim::ScenarioSource src(sim::build_scenario(sim::load_scenario(path.string())));
    const auto& c = src.scenario().rig.camera;
    PinholeRadtanCamera::Params p;
    p.width = c.width, p.height = c.height, p.fx = c.fx, p.fy = c.fy, p.cx = c.cx, p.cy = c.cy;
    p.distortion = RadtanDistortion{c.k1, c.k2, c.p1, c.p2};
    const auto cam = std::make_shared<const PinholeRadtanCamera>(p);
    std::vector<StereoFrame> frames;
    SensorEvent e;
    while (src.next(e))
      if (auto* f = std::get_if<StereoFrame>(&e)) frames.push_back(*f);
    run_variants(args, "sim", frames, cam, cam);
  }
  if (args.euroc) {
    const std::string dir = std::string(DYNAVINS_SHARED_DIR) + "/data/euroc_v1_01_micro";
    const io::EurocDataset data(dir);
    const auto c0 = tracker::load_kalibr_camera(dir + "/mav0/cam0/sensor.yaml");
    const auto c1 = tracker::load_kalibr_camera(dir + "/mav0/cam1/sensor.yaml");
    std::vector<StereoFrame> frames;
    for (std::size_t i = 0; i < data.frames().size(); ++i) frames.push_back(data.load(i));
    run_variants(args, "euroc", frames, c0.camera, c1.camera);
  }
  return 0;
}
