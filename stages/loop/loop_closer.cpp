// The loop-closure stage's per-keyframe logic (see loop_closer.hpp): paper IV-A..C over place/ and graph/.
#include "stages/loop/loop_closer.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <spdlog/spdlog.h>

#include "stages/loop/graph/pose_graph_4dof.hpp"

namespace dynavins::loop {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

RigidPose body_pose(const KeyframeDescriptors& d) { return RigidPose{d.p_wb, d.q_wb.normalized()}; }

std::vector<int64_t> tracked_ids(const KeyframeDescriptors& d) {
  std::vector<int64_t> ids;
  ids.reserve(d.points.size());
  for (const KeyframePoint& p : d.points)
    if (p.id >= 0) ids.push_back(p.id);
  return ids;  // KeyframeGrouper sorts and de-duplicates
}

}  // namespace

LoopCloser::LoopCloser(std::shared_ptr<const VocabularyTree> vocabulary, const LoopCloserOptions& options,
                       Undistort undistort)
    : vocabulary_(std::move(vocabulary)),
      options_(options),
      undistort_(std::move(undistort)),
      verifier_(options.verifier),
      grouper_(options.grouping),
      optimizer_(options.graph) {
  if (!vocabulary_ || vocabulary_->empty()) throw std::invalid_argument("LoopCloser: needs a non-empty vocabulary");
}

LoopCloserOutput LoopCloser::add_keyframe(const Keyframe& keyframe) {
  const auto t0 = Clock::now();
  KeyframeDescriptors d = compute_keyframe_descriptors(keyframe, options_.descriptors, undistort_);
  return process(std::move(d), ms_since(t0));
}

LoopCloserOutput LoopCloser::add_descriptors(KeyframeDescriptors descriptors) {
  return process(std::move(descriptors), 0.0);
}

LoopCloserOutput LoopCloser::process(KeyframeDescriptors d, double descriptors_ms) {
  if (!t_ns_.empty() && d.t_ns <= t_ns_.back())
    throw std::invalid_argument("LoopCloser: keyframes must come in strictly increasing time order");
  if (d.descriptors.rows != static_cast<int>(d.points.size()))
    throw std::invalid_argument("LoopCloser: one descriptor row per point expected");
  LoopCloserOutput out;
  out.t_ns = d.t_ns;
  out.keyframe_index = entries_.size();
  out.timing.descriptors_ms = descriptors_ms;

  // A point the robust BA gave a low weight is likely on a moving object: not a 3-D point for PnP.
  if (options_.use_point_weights)
    for (KeyframePoint& p : d.points)
      if (p.weight < options_.min_point_weight) p.has_p_w = false;

  // IV-A: keyframe grouping on the tracked feature ids.
  const int64_t prev_first = grouper_.open_group().t_ns.empty() ? -1 : grouper_.open_group().first_t_ns();
  const std::optional<KeyframeGroup> closed = grouper_.add_keyframe(d.t_ns, tracked_ids(d));
  out.group_closed = prev_first >= 0 && grouper_.open_group().first_t_ns() != prev_first;
  const RigidPose T_W_k = body_pose(d);
  optimizer_.add_keyframe(d.t_ns, T_W_k);
  if (closed) optimizer_.add_group(*closed);
  const int64_t group_first_t_ns = grouper_.open_group().first_t_ns();

  // IV-B: up to three similar keyframes C_m with m < i, outside the query's recent neighbourhood.
  auto t0 = Clock::now();
  const BowVector bow = vocabulary_->transform(d.descriptors);
  DatabaseQueryOptions q;
  q.max_results = options_.max_candidates;
  q.min_score = options_.min_candidate_score;
  q.exclude_recent = options_.exclude_recent_keyframes;
  q.max_t_ns = group_first_t_ns - 1;
  if (options_.min_candidate_age_s > 0.0)
    q.max_t_ns = std::min(q.max_t_ns, d.t_ns - static_cast<int64_t>(options_.min_candidate_age_s * 1e9));
  const std::vector<PlaceCandidate> candidates = database_.query(bow, q);
  database_.add(static_cast<int64_t>(entries_.size()), d.t_ns, bow);
  out.timing.query_ms = ms_since(t0);
  out.candidates = static_cast<int>(candidates.size());

  t0 = Clock::now();
  for (const PlaceCandidate& c : candidates) {
    const LoopVerification v = verifier_.verify(d, entries_[static_cast<std::size_t>(c.keyframe_id)]);
    // The PnP pose is printed once it passed the inlier count, so an implausible one shows how far off it is.
    const bool has_pose = v.accepted || v.rejection == LoopRejection::Implausible;
    spdlog::debug("loop candidate: query {} match {} score {:.3f} matches {} inliers {} -> {}{}", d.t_ns,
                  entries_[static_cast<std::size_t>(c.keyframe_id)].t_ns, c.score, v.matches, v.inliers,
                  v.accepted ? "verified" : to_string(v.rejection),
                  has_pose ? fmt::format(" (|p_mq| {:.2f} m, rotation {:.1f} deg)", v.loop.p_mq.norm(),
                                         Eigen::AngleAxisd(v.loop.q_mq).angle() * 180.0 / M_PI)
                           : std::string());
    if (!v.accepted) continue;
    const std::size_t index = optimizer_.loops().size();
    if (!optimizer_.add_loop(v.loop)) continue;
    out.new_loops.push_back(NewLoop{v.loop, index, group_first_t_ns, c.score, v.matches});
  }
  out.timing.verification_ms = ms_since(t0);

  t_ns_.push_back(d.t_ns);
  odometry_.push_back(T_W_k);
  corrected_.push_back(compose(drift_, T_W_k));
  entries_.push_back(std::move(d));
  released_.push_back(false);

  // IV-C: optimise once the group holding new loops has closed (its hypotheses are then complete), and
  // on a large graph not before min_new_keyframe_fraction of it is new (cost per keyframe bounded).
  const double new_keyframes = static_cast<double>(t_ns_.size() - keyframes_at_last_optimization_);
  if (out.group_closed && optimizer_.loops().size() > loops_at_last_optimization_ &&
      new_keyframes >= options_.min_new_keyframe_fraction * static_cast<double>(t_ns_.size()))
    run_optimization(out);
  out.drift = drift_;
  return out;
}

LoopCloserOutput LoopCloser::finish() {
  LoopCloserOutput out;
  out.t_ns = t_ns_.empty() ? 0 : t_ns_.back();
  out.keyframe_index = t_ns_.empty() ? 0 : t_ns_.size() - 1;
  const bool had_open = !grouper_.open_group().t_ns.empty();
  const std::optional<KeyframeGroup> closed = grouper_.finish();
  out.group_closed = had_open;
  if (closed) optimizer_.add_group(*closed);
  if (!optimizer_.loops().empty()) run_optimization(out);
  out.drift = drift_;
  return out;
}

void LoopCloser::run_optimization(LoopCloserOutput& out) {
  if (options_.mode == LoopMode::Off) return;  // odometry stays the answer
  const auto t0 = Clock::now();
  const bool warm = options_.warm_start && num_optimizations_ > 0;
  last_result_ = optimizer_.optimize(options_.mode, warm ? &last_result_ : nullptr);
  out.timing.optimization_ms = ms_since(t0);
  out.optimized = true;
  ++num_optimizations_;
  corrected_ = options_.refine_adopted && options_.mode == LoopMode::Dynavins ? refine_with_adopted(last_result_)
                                                                              : last_result_.poses;
  drift_ = drift_correction(odometry_.back(), corrected_.back());
  if (options_.release_revisited) release_revisited(last_result_);
  out.keyframe_t_ns = t_ns_;
  out.corrected = corrected_;

  // Hypotheses of the groups holding the loops verified since the previous optimisation.
  std::vector<int> groups;
  for (std::size_t l = loops_at_last_optimization_; l < last_result_.loops.size(); ++l) {
    const int g = last_result_.loops[l].group;
    if (g >= 0 && std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  }
  for (const GroupWeights& w : last_result_.groups) {
    if (std::find(groups.begin(), groups.end(), w.group) == groups.end()) continue;
    out.hypotheses.push_back(HypothesisReport{
        w.group, optimizer_.groups()[static_cast<std::size_t>(w.group)].first_t_ns(), w.h0, w.h1, w.w0, w.w1});
  }
  loops_at_last_optimization_ = optimizer_.loops().size();
  keyframes_at_last_optimization_ = t_ns_.size();
  spdlog::debug("loop closer: {} optimisation over {} keyframes, {} loops, {} groups: {:.1f} ms",
                loop_mode_name(options_.mode), t_ns_.size(), optimizer_.loops().size(), optimizer_.groups().size(),
                out.timing.optimization_ms);
}

std::vector<RigidPose> LoopCloser::refine_with_adopted(const LoopGraphResult& result) const {
  auto node_of = [&](int64_t t) { return static_cast<int>(keyframe_index(t)); };
  std::vector<LoopEdge> edges;
  const std::vector<VerifiedLoop>& loops = optimizer_.loops();
  for (const LoopResult& r : result.loops) {
    if (!r.used || r.weight < options_.graph.adopted_min_weight) continue;
    const VerifiedLoop& l = loops[r.loop_index];
    edges.push_back(
        LoopEdge{node_of(l.match_t_ns), node_of(l.query_t_ns), RigidPose{l.p_mq, l.q_mq.normalized()}, 1.0});
  }
  if (edges.empty()) return result.poses;
  PoseGraph4Dof graph(odometry_, options_.graph.graph);
  graph.solve(edges, LoopEdgeLoss::Huber);
  return graph.poses();
}

void LoopCloser::release_revisited(const LoopGraphResult& result) {
  const std::vector<VerifiedLoop>& loops = optimizer_.loops();
  for (const LoopResult& r : result.loops) {
    // Adopted by its weight: also when the correction was not applied (skip_insignificant_correction).
    if (r.weight < options_.graph.adopted_min_weight) continue;
    const std::size_t k = keyframe_index(loops[r.loop_index].query_t_ns);
    if (released_[k]) continue;
    KeyframeDescriptors& e = entries_[k];
    database_.remove(static_cast<int64_t>(k), vocabulary_->transform(e.descriptors));
    e.points = std::vector<KeyframePoint>();  // move-assigned: frees the capacity too (= {} would keep it)
    e.descriptors.release();
    released_[k] = true;
  }
}

std::size_t LoopCloser::keyframe_index(int64_t t_ns) const {
  return static_cast<std::size_t>(std::lower_bound(t_ns_.begin(), t_ns_.end(), t_ns) - t_ns_.begin());
}

std::size_t LoopCloser::num_released() const {
  return static_cast<std::size_t>(std::count(released_.begin(), released_.end(), true));
}

std::vector<KeyframeCorrection> LoopCloser::keyframe_corrections() const {
  std::vector<KeyframeCorrection> c;
  c.reserve(t_ns_.size());
  for (std::size_t k = 0; k < t_ns_.size(); ++k)
    c.push_back(KeyframeCorrection{t_ns_[k], drift_correction(odometry_[k], corrected_[k])});
  return c;
}

std::size_t LoopCloser::memory_bytes() const {
  std::size_t b = sizeof(*this);
  for (const KeyframeDescriptors& e : entries_) b += e.memory_bytes();
  b += database_.memory_bytes() + released_.capacity() / 8;
  b += t_ns_.capacity() * sizeof(int64_t) + (odometry_.capacity() + corrected_.capacity()) * sizeof(RigidPose);
  return b;
}

}  // namespace dynavins::loop
