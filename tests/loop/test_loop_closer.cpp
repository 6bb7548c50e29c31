// LoopCloser (paper IV as one object) on a synthetic world with known truth: the two-lap square of
// loop_graph_scenario.hpp (drifting odometry), static 3-D points with fixed random 32-byte descriptors,
// a forward-looking camera; per keyframe the visible points are projected (feature ids persist while a
// point stays in view, so keyframe groups form), 3-D points are given in the keyframe's drifted odometry
// frame as a window would triangulate them, and KeyframeDescriptors are fabricated (no images). A small
// vocabulary is trained on them. Optionally a "temporarily static object" (a parked bus: a plane of points
// with their own descriptors, occluding what is behind it) stands at place A on lap 1 and 2.5 m further on
// lap 2.
// Measured (Release): 240 verified loops, all true (worst T_m^k error 0.023 m), every lap-2 keyframe past the
// first half side closes one; RMSE odometry 1.09 m -> all 0.12, switchable 0.12, dynavins 0.38 m (eq. 16's
// w/|H| on ~50 loops per group), dynavins + refine_adopted 0.15 m. With the bus: 8 false loops (2.5 m off),
// all 0.21 m, dynavins 0.37 m with the false hypothesis at w < 0.001, switchable 0.13 m. 22 kB per keyframe
// kept; with release_revisited the 64 lap-2 keyframes whose loops were adopted leave the database (4.2 -> 2.5 MB),
// and lap 2 driven once more grows the memory by 1.08x (1.49x keeping every keyframe).
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>

#include <catch2/catch.hpp>

#include "stages/loop/loop_closer.hpp"
#include "stages/loop/trajectory_correction.hpp"
#include "tests/loop/loop_graph_scenario.hpp"

using namespace dynavins;
using namespace dynavins::loop;
using dynavins::loop::test::LoopScenario;

namespace {

constexpr double kFocal = 460.0;

struct WorldOptions {
  bool bus = false;               // the temporarily static object
  double bus_shift_m = 2.5;       // along side 1 (+y) on lap 2
  float lap1_point_weight = 1.f;  // robust-BA weight given to lap-1 points (moving-object test)
};

struct Landmark {
  Eigen::Vector3d p;
  std::array<uint8_t, 32> d;
};

struct World {
  LoopScenario s;
  std::vector<KeyframeDescriptors> keyframes;
  std::vector<int> bus_points_seen;  // per keyframe
  RigidPose T_bc;
};

std::array<uint8_t, 32> random_descriptor(std::mt19937& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  std::array<uint8_t, 32> d{};
  for (auto& b : d) b = static_cast<uint8_t>(byte(rng));
  return d;
}

World make_world(const WorldOptions& o = {}) {
  World w;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-6.0, 16.0), uz(-1.5, 2.5), u01(0.0, 1.0);
  std::normal_distribution<double> px_noise(0.0, 0.3 / kFocal), p_noise(0.0, 0.01);
  std::uniform_int_distribution<int> bit(0, 255);
  std::vector<Landmark> statics(1200);
  for (Landmark& l : statics) l = Landmark{Eigen::Vector3d(ux(rng), ux(rng), uz(rng)), random_descriptor(rng)};
  // The bus: a plane 1.3 m right of lap 1's side 1 (x = 10, driving +y), 5 m long, 2.5 m high.
  std::vector<Landmark> bus(150);
  for (Landmark& l : bus)
    l = Landmark{Eigen::Vector3d(11.3, 2.5 + 5.0 * u01(rng), -1.0 + 2.5 * u01(rng)), random_descriptor(rng)};

  // EuRoC-like rig: camera z along the body x axis.
  w.T_bc = RigidPose{Eigen::Vector3d(0.05, 0.0, 0.0), (Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()) *
                                                       Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()))
                                                          .normalized()};
  std::map<int, int64_t> track_of, prev_track_of;  // landmark (bus: offset 100000) -> feature id
  int64_t next_id = 0;
  for (std::size_t k = 0; k < w.s.gt.size(); ++k) {
    const int lap = static_cast<int>(k) / LoopScenario::kPerLap;
    const RigidPose T_cw = inverse(compose(w.s.gt[k], w.T_bc));
    const RigidPose T_odom_gt = compose(w.s.odom[k], inverse(w.s.gt[k]));  // world point into the odometry frame
    auto project = [&](const Eigen::Vector3d& p, Eigen::Vector3d& pc) {
      pc = T_cw.q * p + T_cw.p;
      return pc.z() > 1.0 && pc.z() < 12.0 && std::abs(pc.x() / pc.z()) < 0.7 && std::abs(pc.y() / pc.z()) < 0.5;
    };
    KeyframeDescriptors kd;
    kd.t_ns = w.s.t_ns[k];
    kd.seq = static_cast<int64_t>(k);
    kd.p_wb = w.s.odom[k].p;
    kd.q_wb = w.s.odom[k].q;
    kd.p_bc = w.T_bc.p;
    kd.q_bc = w.T_bc.q;
    kd.descriptors = cv::Mat(0, 32, CV_8UC1);
    std::map<int, int64_t> tracks;
    auto add = [&](int key, const Landmark& l, const Eigen::Vector3d& p, const Eigen::Vector3d& pc) {
      KeyframePoint pt;
      const auto prev = track_of.find(key);
      pt.id = prev != track_of.end() ? prev->second : next_id++;
      tracks[key] = pt.id;
      pt.xy = pc.head<2>() / pc.z() + Eigen::Vector2d(px_noise(rng), px_noise(rng));
      pt.px = kFocal * pt.xy + Eigen::Vector2d(376.0, 240.0);
      pt.has_p_w = true;
      pt.p_w = T_odom_gt.q * (p + Eigen::Vector3d(p_noise(rng), p_noise(rng), p_noise(rng))) + T_odom_gt.p;
      pt.weight = lap == 0 ? o.lap1_point_weight : 1.f;
      cv::Mat row(1, 32, CV_8UC1);
      std::copy(l.d.begin(), l.d.end(), row.ptr<uint8_t>(0));
      for (int f = 0; f < 4; ++f) {  // each observation sees a few bits differently
        const int b = bit(rng);
        row.at<uint8_t>(0, b / 8) ^= static_cast<uint8_t>(1u << (b % 8));
      }
      kd.points.push_back(pt);
      kd.descriptors.push_back(row);
    };
    // The bus (if any) and the image region it covers: static points behind it are hidden.
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9, zmin = 1e9;
    int seen = 0;
    std::vector<std::pair<int, Eigen::Vector3d>> bus_visible;
    if (o.bus) {
      const Eigen::Vector3d shift(0.0, lap == 0 ? 0.0 : o.bus_shift_m, 0.0);
      for (std::size_t j = 0; j < bus.size(); ++j) {
        Eigen::Vector3d pc;
        const Eigen::Vector3d p = bus[j].p + shift;
        if (!project(p, pc)) continue;
        x0 = std::min(x0, pc.x() / pc.z()), x1 = std::max(x1, pc.x() / pc.z());
        y0 = std::min(y0, pc.y() / pc.z()), y1 = std::max(y1, pc.y() / pc.z());
        zmin = std::min(zmin, pc.z());
        bus_visible.emplace_back(static_cast<int>(j), p);
        ++seen;
      }
    }
    const bool occluding = seen >= 10;
    for (std::size_t j = 0; j < statics.size(); ++j) {
      Eigen::Vector3d pc;
      if (!project(statics[j].p, pc)) continue;
      const double x = pc.x() / pc.z(), y = pc.y() / pc.z();
      if (occluding && x > x0 && x < x1 && y > y0 && y < y1 && pc.z() > zmin) continue;
      add(static_cast<int>(j), statics[j], statics[j].p, pc);
    }
    for (const auto& [j, p] : bus_visible) {
      Eigen::Vector3d pc;
      project(p, pc);
      add(100000 + j + (lap == 0 ? 0 : 50000), bus[static_cast<std::size_t>(j)], p, pc);
    }
    w.bus_points_seen.push_back(seen);
    // A new lap starts new tracks anyway (keyframes 0.5 m apart only within a lap).
    track_of = std::move(tracks);
    w.keyframes.push_back(std::move(kd));
  }
  return w;
}

std::shared_ptr<const VocabularyTree> train_vocabulary(const World& w) {
  std::vector<cv::Mat> training;
  for (std::size_t k = 0; k < w.keyframes.size(); k += 2) training.push_back(w.keyframes[k].descriptors);
  VocabularyOptions vo;
  vo.branching = 10;
  vo.depth = 3;
  vo.max_iterations = 5;
  return std::make_shared<const VocabularyTree>(VocabularyTree::build(training, vo));
}

struct Run {
  std::vector<RigidPose> poses;
  std::vector<VerifiedLoop> loops;
  std::vector<HypothesisReport> hypotheses;  // all reported
  LoopGraphResult result;
  int optimizations = 0;
  std::size_t memory_bytes = 0;
  double max_keyframe_ms = 0.0;
  std::vector<KeyframeCorrection> corrections;
  std::vector<NewLoop> new_loops;  // as the per-keyframe outputs reported them
  std::vector<bool> released;      // per keyframe: taken out of the database as a revisit
};

Run run(const World& w, const std::shared_ptr<const VocabularyTree>& vocab, LoopMode mode,
        LoopCloserOptions opts = {}) {
  opts.mode = mode;
  LoopCloser lc(vocab, opts);
  Run r;
  for (const KeyframeDescriptors& kd : w.keyframes) {
    const LoopCloserOutput out = lc.add_descriptors(kd);
    const double ms = out.timing.query_ms + out.timing.verification_ms + out.timing.optimization_ms;
    r.max_keyframe_ms = std::max(r.max_keyframe_ms, ms);
    r.hypotheses.insert(r.hypotheses.end(), out.hypotheses.begin(), out.hypotheses.end());
    r.new_loops.insert(r.new_loops.end(), out.new_loops.begin(), out.new_loops.end());
  }
  const LoopCloserOutput fin = lc.finish();
  r.hypotheses.insert(r.hypotheses.end(), fin.hypotheses.begin(), fin.hypotheses.end());
  r.poses = lc.corrected_poses();
  r.loops = lc.loops();
  r.result = lc.last_result();
  r.optimizations = lc.num_optimizations();
  r.memory_bytes = lc.memory_bytes();
  r.corrections = lc.keyframe_corrections();
  r.released = lc.released();
  return r;
}

/// Index of a keyframe by t_ns in the scenario.
std::size_t index_of(const LoopScenario& s, int64_t t_ns) {
  return static_cast<std::size_t>(std::lower_bound(s.t_ns.begin(), s.t_ns.end(), t_ns) - s.t_ns.begin());
}

/// Translation error of a loop's T_m^k against the truth.
double loop_error_m(const LoopScenario& s, const VerifiedLoop& l) {
  const RigidPose& m = s.gt[index_of(s, l.match_t_ns)];
  const RigidPose& k = s.gt[index_of(s, l.query_t_ns)];
  return (compose(inverse(m), k).p - l.p_mq).norm();
}

}  // namespace

/// Mean over the lap-2 groups: whether each lap-2 keyframe got at least one loop.
double lap2_recall(const LoopScenario& s, const std::vector<VerifiedLoop>& loops) {
  std::set<std::size_t> with_loop;
  for (const VerifiedLoop& l : loops) with_loop.insert(index_of(s, l.query_t_ns));
  std::size_t n = 0;
  for (std::size_t k = LoopScenario::kPerLap + LoopScenario::kPerSide / 2; k < s.gt.size(); ++k)
    n += with_loop.count(k);
  return static_cast<double>(n) / static_cast<double>(s.gt.size() - LoopScenario::kPerLap - LoopScenario::kPerSide / 2);
}

TEST_CASE("LoopCloser: true revisits are detected and verified", "[loop][closer]") {
  const World w = make_world();
  const auto vocab = train_vocabulary(w);
  const Run r = run(w, vocab, LoopMode::Dynavins);
  // Every verified loop joins a lap-2 query to a lap-1 match with the true relative pose.
  REQUIRE(r.loops.size() >= 100);
  double worst = 0.0;
  for (const VerifiedLoop& l : r.loops) {
    CHECK(index_of(w.s, l.query_t_ns) >= static_cast<std::size_t>(LoopScenario::kPerLap));
    CHECK(index_of(w.s, l.match_t_ns) < static_cast<std::size_t>(LoopScenario::kPerLap));
    CHECK(l.inliers >= 15);
    worst = std::max(worst, loop_error_m(w.s, l));
  }
  CHECK(worst < 0.05);
  // Candidates are older than the query group's first keyframe (m < i) and outside the last 30 keyframes.
  REQUIRE(r.new_loops.size() == r.loops.size());
  for (const NewLoop& nl : r.new_loops) {
    CHECK(nl.loop.match_t_ns < nl.group_first_t_ns);
    CHECK(index_of(w.s, nl.loop.query_t_ns) - index_of(w.s, nl.loop.match_t_ns) > 30);
  }
  // Nearly every lap-2 keyframe (after the first half side, whose C_m would be within the exclusion) closes a loop.
  CHECK(lap2_recall(w.s, r.loops) > 0.9);
  // Groups form on the persistent feature ids: one per side of the square (the corners break the tracks),
  // and the run's last five keyframes (a group started there), under min_group_size but kept by finish()
  // (keep_last_group); the paper drops that group, and its loops with it.
  CHECK(r.result.groups.size() == 5);  // lap-2 groups with loops
  LoopCloserOptions paper;
  paper.grouping.keep_last_group = false;
  const Run dropped = run(w, vocab, LoopMode::Dynavins, paper);
  CHECK(dropped.result.groups.size() == 4);
  std::size_t grouped = 0;
  for (const LoopResult& l : dropped.result.loops) grouped += l.group >= 0 ? 1 : 0;
  CHECK(grouped < dropped.loops.size());
  WARN("loops " << r.loops.size() << ", worst T_m^k error " << worst << " m, lap-2 recall " << lap2_recall(w.s, r.loops)
                << ", optimisations " << r.optimizations << ", slowest keyframe " << r.max_keyframe_ms << " ms");
}

TEST_CASE("LoopCloser: off keeps the odometry, all and dynavins remove most of the drift", "[loop][closer]") {
  const World w = make_world();
  const auto vocab = train_vocabulary(w);
  const double odom = w.s.rmse(w.s.odom);
  const Run off = run(w, vocab, LoopMode::Off);
  CHECK(off.optimizations == 0);
  for (std::size_t k = 0; k < w.s.odom.size(); ++k) REQUIRE((off.poses[k].p - w.s.odom[k].p).norm() < 1e-12);
  const Run all = run(w, vocab, LoopMode::All);
  const Run dyn = run(w, vocab, LoopMode::Dynavins);
  WARN("RMSE odometry " << odom << " m, all " << w.s.rmse(all.poses) << " m, dynavins " << w.s.rmse(dyn.poses) << " m");
  CHECK(odom > 1.0);
  CHECK(w.s.rmse(all.poses) < 0.2 * odom);
  CHECK(w.s.rmse(dyn.poses) < 0.45 * odom);
  const Run sw = run(w, vocab, LoopMode::Switchable);
  WARN("RMSE switchable " << w.s.rmse(sw.poses) << " m");
  CHECK(w.s.rmse(sw.poses) < 0.45 * odom);
  CHECK(w.s.end_error(all.poses) < 0.3 * w.s.end_error(w.s.odom));
  CHECK(w.s.end_error(dyn.poses) < 0.5 * w.s.end_error(w.s.odom));
}

namespace {
/// The loops of a run that the relocated bus produced (T_m^k off by more than 1 m).
std::vector<std::size_t> false_loops(const World& w, const Run& r) {
  std::vector<std::size_t> f;
  for (std::size_t l = 0; l < r.loops.size(); ++l)
    if (loop_error_m(w.s, r.loops[l]) > 1.0) f.push_back(l);
  return f;
}
}  // namespace

TEST_CASE("LoopCloser: a relocated object gives false loops that bend `all`", "[loop][closer]") {
  const World clean = make_world(), bus = make_world(WorldOptions{true});
  const Run a_clean = run(clean, train_vocabulary(clean), LoopMode::All);
  const auto bus_vocab = train_vocabulary(bus);
  const Run a_bus = run(bus, bus_vocab, LoopMode::All);
  const std::vector<std::size_t> f = false_loops(bus, a_bus);
  WARN("false loops " << f.size() << " of " << a_bus.loops.size() << "; RMSE all: clean " << clean.s.rmse(a_clean.poses)
                      << " m, with the bus " << bus.s.rmse(a_bus.poses) << " m");
  CHECK(false_loops(clean, a_clean).empty());
  CHECK(f.size() >= 5);
  for (std::size_t l : f) CHECK(std::abs(loop_error_m(bus.s, a_bus.loops[l]) - 2.5) < 0.8);  // the bus' shift
  CHECK(bus.s.rmse(a_bus.poses) > clean.s.rmse(a_clean.poses) + 0.05);
  // For reference (no claim): switchable constraints on the same loops.
  const Run s_bus = run(bus, bus_vocab, LoopMode::Switchable);
  int false_switched_off = 0;
  for (std::size_t l : f) false_switched_off += s_bus.result.loops[l].weight < 0.5 ? 1 : 0;
  WARN("RMSE switchable with the bus " << bus.s.rmse(s_bus.poses)
                                       << " m; false loops with s < 0.5: " << false_switched_off << " of " << f.size());
}

TEST_CASE("LoopCloser: dynavins gives the relocated object's hypothesis a low weight", "[loop][closer]") {
  const World clean = make_world(), bus = make_world(WorldOptions{true});
  const Run d_clean = run(clean, train_vocabulary(clean), LoopMode::Dynavins);
  const Run d_bus = run(bus, train_vocabulary(bus), LoopMode::Dynavins);
  const std::vector<std::size_t> f = false_loops(bus, d_bus);
  REQUIRE(f.size() >= 5);
  // Every false loop sits in a hypothesis of its group that ends with a low weight; that group's other
  // hypothesis (the true loops) keeps a high one.
  for (std::size_t l : f) {
    const LoopResult& lr = d_bus.result.loops[l];
    CHECK(lr.group >= 0);
    CHECK(lr.weight < 0.05);
  }
  int groups_with_false = 0;
  for (const GroupWeights& g : d_bus.result.groups) {
    const bool h0_false = !g.h0.empty() && std::count(f.begin(), f.end(), g.h0.front()) > 0;
    const bool h1_false = !g.h1.empty() && std::count(f.begin(), f.end(), g.h1.front()) > 0;
    if (!h0_false && !h1_false) continue;
    ++groups_with_false;
    CHECK((h0_false ? g.w0 : g.w1) < 0.05);
    CHECK((h0_false ? g.w1 : g.w0) > 0.5);
    WARN("group " << g.group << ": |H0| " << g.h0.size() << " w0 " << g.w0 << ", |H1| " << g.h1.size() << " w1 "
                  << g.w1);
  }
  CHECK(groups_with_false >= 1);
  // The hypotheses were also reported in the per-keyframe outputs.
  CHECK(!d_bus.hypotheses.empty());
  const double e_clean = clean.s.rmse(d_clean.poses), e_bus = bus.s.rmse(d_bus.poses);
  WARN("RMSE dynavins: true loops only " << e_clean << " m, with the bus " << e_bus << " m");
  CHECK(std::abs(e_bus - e_clean) < 0.03);
  CHECK(e_bus < 0.45 * bus.s.rmse(bus.s.odom));
}

TEST_CASE("LoopCloser: refine_adopted re-solves with the adopted hypotheses' loops only", "[loop][closer]") {
  const World clean = make_world(), bus = make_world(WorldOptions{true});
  LoopCloserOptions opts;
  opts.refine_adopted = true;
  const Run r_clean = run(clean, train_vocabulary(clean), LoopMode::Dynavins, opts);
  const Run r_bus = run(bus, train_vocabulary(bus), LoopMode::Dynavins, opts);
  const double e_clean = clean.s.rmse(r_clean.poses), e_bus = bus.s.rmse(r_bus.poses);
  WARN("RMSE dynavins + refine_adopted: true loops only " << e_clean << " m, with the bus " << e_bus << " m");
  // As accurate as `all` on true loops (0.12 m there), and the bus' false loops stay out.
  CHECK(e_clean < 0.2);
  CHECK(std::abs(e_bus - e_clean) < 0.03);
  for (std::size_t l : false_loops(bus, r_bus)) CHECK(r_bus.result.loops[l].weight < 0.05);
}

TEST_CASE("LoopCloser: a camera standing still finds loops only outside its recent keyframes and group",
          "[loop][closer]") {
  const World w = make_world();
  LoopCloserOptions opts;
  opts.mode = LoopMode::All;
  LoopCloser lc(train_vocabulary(w), opts);
  std::vector<NewLoop> loops;
  for (int k = 0; k < 40; ++k) {  // the same view and feature ids: groups of 20 (max_group_size)
    KeyframeDescriptors kd = w.keyframes[10];
    kd.t_ns = w.s.t_ns[static_cast<std::size_t>(k)];
    const LoopCloserOutput out = lc.add_descriptors(kd);
    for (const NewLoop& nl : out.new_loops) {
      // Keyframe k (in the group starting at 20) may match m <= min(19, k - 31) only.
      const auto m = static_cast<int>(index_of(w.s, nl.loop.match_t_ns));
      CHECK(k >= 31);
      CHECK(m <= std::min(19, k - 31));
      CHECK(nl.loop.p_mq.norm() < 0.05);
      loops.push_back(nl);
    }
  }
  CHECK(!loops.empty());
  CHECK(lc.groups().size() == 1);  // the second group is still open
}

TEST_CASE("LoopCloser: low-weight points are not used as the candidate's 3-D points", "[loop][closer]") {
  WorldOptions o;
  o.lap1_point_weight = 0.3f;  // as if lap 1 had been seen on moving objects only
  const World w = make_world(o);
  const auto vocab = train_vocabulary(w);
  const Run on = run(w, vocab, LoopMode::All);
  LoopCloserOptions off_opts;
  off_opts.use_point_weights = false;
  const Run off = run(w, vocab, LoopMode::All, off_opts);
  CHECK(on.loops.empty());
  CHECK(off.loops.size() >= 100);
}

TEST_CASE("LoopCloser: outputs, drift correction, memory per keyframe", "[loop][closer]") {
  const World w = make_world();
  LoopCloserOptions opts;
  opts.mode = LoopMode::All;
  LoopCloser lc(train_vocabulary(w), opts);
  int optimisations = 0, closed = 0;
  for (const KeyframeDescriptors& kd : w.keyframes) {
    const LoopCloserOutput out = lc.add_descriptors(kd);
    CHECK(out.t_ns == kd.t_ns);
    CHECK(out.keyframe_index == lc.num_keyframes() - 1);
    CHECK(out.candidates <= 3);
    CHECK(out.timing.query_ms >= 0.0);
    for (const NewLoop& nl : out.new_loops) {
      CHECK(nl.loop.query_t_ns == kd.t_ns);
      CHECK(nl.group_first_t_ns <= kd.t_ns);
      CHECK(nl.loop_index < lc.loops().size());
    }
    closed += out.group_closed ? 1 : 0;
    if (!out.optimized) {
      CHECK(out.corrected.empty());
      continue;
    }
    ++optimisations;
    CHECK(out.group_closed);
    REQUIRE(out.corrected.size() == lc.num_keyframes());
    CHECK(out.timing.optimization_ms > 0.0);
    // The drift maps the newest keyframe's odometry pose onto its corrected pose.
    const RigidPose c = compose(out.drift, lc.odometry_poses().back());
    CHECK((c.p - out.corrected.back().p).norm() < 1e-9);
    CHECK(c.q.angularDistance(out.corrected.back().q) < 1e-9);
  }
  const LoopCloserOutput fin = lc.finish();
  CHECK(fin.optimized);
  CHECK(optimisations == lc.num_optimizations() - 1);
  CHECK(closed >= 7);  // 8 kept groups (7 closed by a keyframe, the last by finish()) and short dropped ones
  // Keyframes after the last optimisation are corrected with its drift (as VINS-Fusion's r_drift, t_drift).
  const std::vector<KeyframeCorrection> corr = lc.keyframe_corrections();
  REQUIRE(corr.size() == lc.num_keyframes());
  std::vector<StampedPose> kf_odom;
  for (std::size_t k = 0; k < lc.num_keyframes(); ++k)
    kf_odom.push_back(StampedPose{lc.keyframe_t_ns()[k], lc.odometry_poses()[k]});
  const std::vector<StampedPose> kf_corr = correct_trajectory(kf_odom, corr);
  for (std::size_t k = 0; k < kf_corr.size(); ++k)
    CHECK((kf_corr[k].T_W_b.p - lc.corrected_poses()[k].p).norm() < 1e-9);
  const double kb = static_cast<double>(lc.memory_bytes()) / 1024.0 / static_cast<double>(lc.num_keyframes());
  std::size_t points = 0;
  for (const auto& kd : w.keyframes) points += kd.points.size();
  WARN("memory " << kb << " kB per keyframe (" << points / w.keyframes.size() << " points each)");
  CHECK(kb < 40.0);
  CHECK_THROWS_AS(lc.add_descriptors(w.keyframes.back()), std::invalid_argument);  // not newer
}

TEST_CASE("LoopCloser: revisits confirmed by adopted loops leave the database; rejected ones stay", "[loop][closer]") {
  const World w = make_world();
  const auto vocab = train_vocabulary(w);
  LoopCloserOptions keep;
  keep.release_revisited = false;
  const Run kept = run(w, vocab, LoopMode::Dynavins, keep);
  const Run rel = run(w, vocab, LoopMode::Dynavins);
  std::size_t released = 0;
  for (std::size_t k = 0; k < rel.released.size(); ++k) {
    released += rel.released[k];
    if (rel.released[k]) CHECK(k >= static_cast<std::size_t>(LoopScenario::kPerLap));  // only lap 2 revisits lap 1
  }
  WARN("released " << released << " of " << rel.released.size() << " keyframes; memory " << kept.memory_bytes / 1024
                   << " -> " << rel.memory_bytes / 1024 << " kB");
  CHECK(std::count(kept.released.begin(), kept.released.end(), true) == 0);
  CHECK(static_cast<double>(released) > 0.4 * LoopScenario::kPerLap);
  CHECK(static_cast<double>(rel.memory_bytes) < 0.85 * static_cast<double>(kept.memory_bytes));
  // Two laps: lap-2 queries only ever match lap-1 keyframes, so the loops and the answer are the same.
  REQUIRE(rel.loops.size() == kept.loops.size());
  for (std::size_t k = 0; k < rel.poses.size(); ++k) CHECK((rel.poses[k].p - kept.poses[k].p).norm() < 1e-6);

  // The relocated bus: a keyframe is released only for a loop its optimisation adopted, never for the
  // false loops the weights rejected.
  const World bus = make_world(WorldOptions{true});
  const Run b = run(bus, train_vocabulary(bus), LoopMode::Dynavins);
  std::map<std::size_t, bool> adopted;  // query keyframe -> one of its loops at weight >= 0.5
  for (const LoopResult& r : b.result.loops) {
    const std::size_t q = index_of(bus.s, b.loops[r.loop_index].query_t_ns);
    adopted[q] = adopted[q] || r.weight >= 0.5;
  }
  int rejected_only = 0;
  for (std::size_t k = 0; k < b.released.size(); ++k) {
    const bool has_loops = adopted.count(k) > 0;
    if (b.released[k]) CHECK((has_loops && adopted[k]));
    rejected_only += has_loops && !adopted[k];
  }
  WARN("bus: " << false_loops(bus, b).size() << " false loops; " << rejected_only
               << " keyframes whose loops were all rejected, none released");
}

TEST_CASE("LoopCloser: a route driven again does not grow the database", "[loop][closer]") {
  // Laps 1 and 2, then lap 2's keyframes once more as a third lap (times shifted): with release_revisited
  // the third lap's keyframes find lap 1 or lap 2 and leave the database too.
  const World w = make_world();
  const auto vocab = train_vocabulary(w);
  for (bool release : {false, true}) {
    LoopCloserOptions opts;
    opts.release_revisited = release;
    LoopCloser lc(vocab, opts);
    for (const KeyframeDescriptors& kd : w.keyframes) lc.add_descriptors(kd);
    const std::size_t after_two = lc.memory_bytes();
    const int64_t shift = w.keyframes.back().t_ns - w.keyframes.front().t_ns + 100'000'000;
    for (std::size_t k = LoopScenario::kPerLap; k < w.keyframes.size(); ++k) {
      KeyframeDescriptors kd = w.keyframes[k];
      kd.t_ns += shift;
      lc.add_descriptors(kd);
    }
    lc.finish();
    const double growth = static_cast<double>(lc.memory_bytes()) / static_cast<double>(after_two);
    WARN((release ? "release_revisited" : "keep all")
         << ": memory after the third lap " << growth << "x that after two; " << lc.num_released() << " released");
    if (release) CHECK(growth < 1.15);
    else CHECK(growth > 1.3);
  }
}

TEST_CASE("LoopCloser: optimisations are spaced in proportion to the graph's size", "[loop][closer]") {
  // min_new_keyframe_fraction at 0.3 on the 160-keyframe scene stands for 0.01 on a 30-minute run.
  const World w = make_world();
  const auto vocab = train_vocabulary(w);
  std::vector<std::size_t> at[2];  // keyframe counts at each optimisation: fraction 0, 0.3
  std::vector<RigidPose> poses[2];
  for (int f = 0; f < 2; ++f) {
    LoopCloserOptions opts;
    opts.min_new_keyframe_fraction = f == 0 ? 0.0 : 0.3;
    LoopCloser lc(vocab, opts);
    for (const KeyframeDescriptors& kd : w.keyframes)
      if (lc.add_descriptors(kd).optimized) at[f].push_back(lc.num_keyframes());
    CHECK(lc.finish().optimized);
    poses[f] = lc.corrected_poses();
  }
  WARN("optimisations before finish(): " << at[0].size() << " at every group closing, " << at[1].size()
                                         << " spaced by 30 % of the graph");
  REQUIRE(at[0].size() >= 3);
  CHECK(at[1].size() < at[0].size());
  CHECK(!at[1].empty());
  for (std::size_t i = 1; i < at[1].size(); ++i)
    CHECK(static_cast<double>(at[1][i] - at[1][i - 1]) >= 0.3 * static_cast<double>(at[1][i]));
  // finish() optimises the whole graph either way: the same final answer (warm starts from other points).
  CHECK(w.s.rmse(poses[1]) < w.s.rmse(poses[0]) + 0.02);
}

TEST_CASE("LoopCloser: a keyframe with an image keeps descriptors, not the image", "[loop][closer]") {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> gray(0, 255);
  cv::Mat img(480, 752, CV_8UC1);
  for (int y = 0; y < img.rows; y += 8)  // 8x8 blocks of random gray: plenty of corners
    for (int x = 0; x < img.cols; x += 8) img(cv::Rect(x, y, 8, 8)).setTo(gray(rng));
  std::vector<cv::Mat> training{cv::Mat(200, 32, CV_8UC1)};
  for (int r = 0; r < 200; ++r)
    for (int c = 0; c < 32; ++c) training[0].at<uint8_t>(r, c) = static_cast<uint8_t>(gray(rng));
  VocabularyOptions vo;
  vo.branching = 4;
  vo.depth = 2;
  LoopCloser lc(std::make_shared<const VocabularyTree>(VocabularyTree::build(training, vo)));
  for (int k = 0; k < 3; ++k) {
    Keyframe kf;
    kf.t_ns = 1'000'000'000LL * (k + 1);
    kf.image = img;
    for (int i = 0; i < 50; ++i) {
      KeyframePoint p;
      p.id = i;
      p.px = Eigen::Vector2d(60 + 12 * i, 100 + 5 * (i % 40));
      p.xy = (p.px - Eigen::Vector2d(376, 240)) / kFocal;
      kf.points.push_back(p);
    }
    const LoopCloserOutput out = lc.add_keyframe(kf);
    CHECK(out.timing.descriptors_ms > 0.0);
  }
  const double per_kf = static_cast<double>(lc.memory_bytes()) / 3.0;
  WARN("with a 752x480 image (" << img.total() / 1024 << " kB): " << per_kf / 1024.0 << " kB per keyframe");
  CHECK(per_kf < 0.25 * static_cast<double>(img.total()));
}

TEST_CASE("correct_trajectory: each frame takes the correction of the latest keyframe at or before it",
          "[loop][closer]") {
  const RigidPose shift{Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Quaterniond::Identity()};
  const RigidPose turn{Eigen::Vector3d(0.0, 2.0, 0.0), quat_from_ypr(M_PI / 2, 0.0, 0.0)};
  const std::vector<KeyframeCorrection> corr{{10, shift}, {20, turn}};
  const RigidPose p{Eigen::Vector3d(1.0, 0.0, 0.5), quat_from_ypr(0.1, 0.0, 0.0)};
  const std::vector<StampedPose> odom{{25, p}, {5, p}, {10, p}, {15, p}, {20, p}};
  const std::vector<StampedPose> c = correct_trajectory(odom, corr);
  REQUIRE(c.size() == 5);
  for (std::size_t i = 0; i < 5; ++i) CHECK(c[i].t_ns == odom[i].t_ns);
  CHECK((c[1].T_W_b.p - p.p).norm() < 1e-12);  // before the first keyframe: unchanged
  for (int i : {2, 3}) CHECK((c[static_cast<std::size_t>(i)].T_W_b.p - Eigen::Vector3d(2.0, 0.0, 0.5)).norm() < 1e-12);
  for (int i : {0, 4}) {
    CHECK((c[static_cast<std::size_t>(i)].T_W_b.p - Eigen::Vector3d(0.0, 3.0, 0.5)).norm() < 1e-12);
    CHECK(std::abs(yaw_of(c[static_cast<std::size_t>(i)].T_W_b.q) - (M_PI / 2 + 0.1)) < 1e-12);
  }
  CHECK(correct_trajectory(odom, {}).size() == 5);
  // drift_correction is what maps an odometry pose onto its corrected pose.
  const RigidPose d = drift_correction(p, compose(turn, p));
  CHECK((d.p - turn.p).norm() < 1e-12);
  CHECK(d.q.angularDistance(turn.q) < 1e-12);
}

// Hidden (run by name or "[.diag]"): prints the world and every loop; BUS=1 in the environment adds the bus.
TEST_CASE("LoopCloser: world diagnostics", "[loop][closer][.diag]") {
  const World w = make_world(WorldOptions{getenv("BUS") != nullptr});
  std::size_t total = 0, minp = 100000;
  for (const auto& kd : w.keyframes) total += kd.points.size(), minp = std::min(minp, kd.points.size());
  WARN("points per keyframe: mean " << total / w.keyframes.size() << " min " << minp);
  std::string bus;
  for (std::size_t k = 0; k < w.keyframes.size(); ++k)
    if (w.bus_points_seen[k] > 0) bus += std::to_string(k) + ":" + std::to_string(w.bus_points_seen[k]) + " ";
  WARN("bus seen: " << bus);
  const auto vocab = train_vocabulary(w);
  for (LoopMode m : {LoopMode::All, LoopMode::Dynavins}) {
    LoopCloserOptions opts;
    opts.mode = m;
    LoopCloser lc(vocab, opts);
    std::string log;
    for (const auto& kd : w.keyframes) {
      const auto out = lc.add_descriptors(kd);
      for (const auto& nl : out.new_loops)
        log += std::to_string(index_of(w.s, nl.loop.query_t_ns)) + "->" +
               std::to_string(index_of(w.s, nl.loop.match_t_ns)) + "(" + std::to_string(nl.loop.inliers) + "," +
               std::to_string(loop_error_m(w.s, nl.loop)).substr(0, 4) + ") ";
      for (const auto& h : out.hypotheses)
        log += "\n  H g" + std::to_string(h.group) + " |H0|=" + std::to_string(h.h0.size()) +
               " w0=" + std::to_string(h.w0) + " |H1|=" + std::to_string(h.h1.size()) + " w1=" + std::to_string(h.w1) +
               "\n";
    }
    lc.finish();
    std::string groups;
    for (const auto& g : lc.groups())
      groups += std::to_string(index_of(w.s, g.first_t_ns())) + "+" + std::to_string(g.t_ns.size()) + " ";
    WARN(loop_mode_name(m) << ": groups " << groups << "\nloops " << log << "\nrmse odom " << w.s.rmse(w.s.odom)
                           << " corrected " << w.s.rmse(lc.corrected_poses()) << " optimisations "
                           << lc.num_optimizations());
  }
}
