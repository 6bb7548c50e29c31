#include "sim/scenario/scenario_spec.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <stdexcept>

#include <opencv2/core.hpp>

namespace dynavins::sim {
namespace {

struct Reader {
  std::string file;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw std::runtime_error(file + ": " + key + ": " + problem);
  }
  /// Every key of `node` must be in `allowed` (typos are errors, not silently ignored settings).
  void only(const cv::FileNode& node, const std::string& where, const std::set<std::string>& allowed) const {
    for (const auto& key : node.keys())
      if (!allowed.count(key)) fail(where.empty() ? key : where + "." + key, "unknown key");
  }
  double number(const cv::FileNode& node, const std::string& key, bool required, double fallback) const {
    const cv::FileNode n = node[key];
    if (n.empty()) {
      if (required) fail(key, "missing");
      return fallback;
    }
    if (!n.isReal() && !n.isInt()) fail(key, "must be a number");
    return static_cast<double>(n);
  }
  std::string text(const cv::FileNode& node, const std::string& key, const std::string& fallback,
                   const std::set<std::string>& choices) const {
    const cv::FileNode n = node[key];
    if (n.empty()) return fallback;
    if (!n.isString()) fail(key, "must be a string");
    const std::string v = static_cast<std::string>(n);
    if (!choices.empty() && !choices.count(v)) {
      std::string all;
      for (const auto& c : choices) all += (all.empty() ? "" : "|") + c;
      fail(key, "'" + v + "' is not one of " + all);
    }
    return v;
  }
  std::vector<double> numbers(const cv::FileNode& node, const std::string& key, std::size_t multiple) const {
    const cv::FileNode n = node[key];
    if (n.empty() || !n.isSeq()) fail(key, "missing or not a list");
    std::vector<double> v;
    for (const auto& x : n) {
      if (!x.isReal() && !x.isInt()) fail(key, "holds a non-number");
      v.push_back(static_cast<double>(x));
    }
    if (v.empty() || v.size() % multiple) fail(key, "needs groups of " + std::to_string(multiple) + " numbers");
    return v;
  }
};

MovingObjectSpec read_object(const Reader& r, const cv::FileNode& n, const std::string& where) {
  MovingObjectSpec o;
  const std::string kind = r.text(n, "kind", "car", {"car", "truck", "board"});
  o.kind = kind == "truck" ? ObjectKind::Truck : kind == "board" ? ObjectKind::Board : ObjectKind::Car;
  const std::string motion = r.text(n, "motion", "", {"lane", "cross_ahead", "follow", "relocate"});
  if (motion.empty()) r.fail(where + ".motion", "missing");
  Reader in{r.file};
  if (motion == "lane") {
    r.only(n, where, {"kind", "motion", "x0", "y", "speed", "t0"});
    o.motion = ObjectMotion::Lane;
    o.x0 = in.number(n, "x0", true, 0);
    o.y = in.number(n, "y", true, 0);
    o.speed = in.number(n, "speed", true, 0);
    o.t0 = in.number(n, "t0", false, 0);
  } else if (motion == "cross_ahead") {
    r.only(n, where, {"kind", "motion", "t", "distance", "speed"});
    o.motion = ObjectMotion::CrossAhead;
    o.t = in.number(n, "t", true, 0);
    o.distance = in.number(n, "distance", true, 0);
    o.speed = in.number(n, "speed", true, 0);
  } else if (motion == "follow") {
    r.only(n, where, {"kind", "motion", "distance", "offset"});
    o.motion = ObjectMotion::Follow;
    o.distance = in.number(n, "distance", true, 0);
    o.offset = in.number(n, "offset", false, 0);
  } else {
    r.only(n, where, {"kind", "motion", "poses"});
    o.motion = ObjectMotion::Relocate;
    const auto v = in.numbers(n, "poses", 4);
    for (std::size_t i = 0; i < v.size(); i += 4) o.poses.emplace_back(v[i], v[i + 1], v[i + 2], v[i + 3]);
    for (std::size_t i = 1; i < o.poses.size(); ++i)
      if (o.poses[i][0] <= o.poses[i - 1][0]) r.fail(where + ".poses", "times must increase");
  }
  return o;
}

}  // namespace

ScenarioSpec load_scenario(const std::string& path) {
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ)) throw std::runtime_error("cannot open");
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path + ": not a readable YAML scenario: " + e.what());
  } catch (const std::runtime_error&) {
    throw std::runtime_error(path + ": cannot open the scenario file");
  }
  const Reader r{path};
  const cv::FileNode root = fs.root();
  r.only(root, "", {"name", "seed", "duration", "world", "motion", "photometric", "rig", "objects"});
  ScenarioSpec s;
  s.file = path;
  s.name = r.text(root, "name", "", {});
  if (s.name.empty()) r.fail("name", "missing");
  s.seed = static_cast<uint64_t>(r.number(root, "seed", false, 1));
  s.duration = r.number(root, "duration", false, 0);
  if (s.duration < 0) r.fail("duration", "must be >= 0");
  s.photometric = r.text(root, "photometric", "day", {"day", "night"});
  s.rig = r.text(root, "rig", "euroc", {"euroc", "viode"});

  const cv::FileNode world = root["world"];
  if (!world.empty()) {
    r.only(world, "world", {"x_min", "x_max", "seed", "avenues", "cross_streets"});
    s.world_x_min = r.number(world, "x_min", false, s.world_x_min);
    s.world_x_max = r.number(world, "x_max", false, s.world_x_max);
    s.world_seed = static_cast<uint64_t>(r.number(world, "seed", false, static_cast<double>(s.world_seed)));
    if (s.world_x_max <= s.world_x_min) r.fail("world.x_max", "must exceed world.x_min");
    if (!world["avenues"].empty()) s.avenue_y = r.numbers(world, "avenues", 1);
    if (!world["cross_streets"].empty()) s.cross_street_x = r.numbers(world, "cross_streets", 1);
    // Two avenues closer than a block would put buildings of one into the other's road.
    std::vector<double> a = s.avenue_y;
    std::sort(a.begin(), a.end());
    for (std::size_t k = 0; k + 1 < a.size(); ++k)
      if (a[k + 1] - a[k] < 50) r.fail("world.avenues", "must be at least 50 m apart (one city block)");
  }

  const cv::FileNode motion = root["motion"];
  if (motion.empty()) r.fail("motion", "missing");
  if (!motion["tum"].empty()) {
    r.only(motion, "motion", {"tum", "tum_start", "placement", "body_axes"});
    const std::string tum = r.text(motion, "tum", "", {});
    if (tum.empty()) r.fail("motion.tum", "must name a TUM trajectory file");
    // Relative paths are relative to the scenario file, so a scenario works from any directory.
    const std::filesystem::path tp(tum);
    s.tum_file = tp.is_absolute() ? tp.string() : (std::filesystem::path(path).parent_path() / tp).string();
    s.tum_start = r.number(motion, "tum_start", false, 0);
    if (s.tum_start < 0) r.fail("motion.tum_start", "must be >= 0");
    if (!motion["placement"].empty()) {
      const auto pl = r.numbers(motion, "placement", 4);
      if (pl.size() != 4) r.fail("motion.placement", "must be [x, y, z, yaw_deg]");
      s.tum_placement = Eigen::Vector4d(pl[0], pl[1], pl[2], pl[3]);
    }
    s.tum_body_axes = r.text(motion, "body_axes", "sim", {"sim", "euroc"});
  } else {
    r.only(motion, "motion", {"profile", "cruise_speed", "waypoints", "dwell"});
    s.profile = r.text(motion, "profile", "drone", {"car", "drone", "handheld"});
    s.cruise_speed = r.number(motion, "cruise_speed", false, 0);
    const auto w = Reader{path}.numbers(motion, "waypoints", 3);
    for (std::size_t i = 0; i < w.size(); i += 3) s.waypoints.emplace_back(w[i], w[i + 1], w[i + 2]);
    if (s.waypoints.size() < 2) r.fail("motion.waypoints", "needs at least two (x, y, z) corners");
    s.dwell.assign(s.waypoints.size(), 0.0);
    if (!motion["dwell"].empty()) {
      const auto d = Reader{path}.numbers(motion, "dwell", 2);
      for (std::size_t i = 0; i < d.size(); i += 2) {
        const double k = d[i];
        if (k != std::floor(k) || k < 0 || k >= static_cast<double>(s.waypoints.size()))
          r.fail("motion.dwell", "waypoint index " + std::to_string(k) + " is not one of the waypoints");
        if (!(d[i + 1] > 0) || d[i + 1] > 3600) r.fail("motion.dwell", "seconds must be in (0, 3600]");
        s.dwell[static_cast<std::size_t>(k)] = d[i + 1];
      }
    }
  }

  const cv::FileNode objects = root["objects"];
  if (!objects.empty()) {
    if (!objects.isSeq()) r.fail("objects", "must be a list");
    int i = 0;
    for (const auto& o : objects) {
      const std::string where = "objects[" + std::to_string(i++) + "]";
      if (!o.isMap()) r.fail(where, "must be a map");
      s.objects.push_back(read_object(r, o, where));
    }
  }
  return s;
}

}  // namespace dynavins::sim
