// Selective global optimisation, paper IV (see loop_graph_optimizer.hpp).
#include "stages/loop/graph/loop_graph_optimizer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "stages/loop/graph/hypothesis_weights.hpp"

namespace dynavins::loop {

LoopGraphOptimizer::LoopGraphOptimizer(const LoopGraphOptions& options) : options_(options) {}

void LoopGraphOptimizer::add_keyframe(int64_t t_ns, const RigidPose& T_W_k_odom) {
  node_of_[t_ns] = static_cast<int>(odometry_.size());
  t_ns_.push_back(t_ns);
  odometry_.push_back(T_W_k_odom);
  group_of_node_.push_back(-1);
}

bool LoopGraphOptimizer::add_group(const KeyframeGroup& group) {
  if (group.t_ns.empty()) return false;
  for (int64_t t : group.t_ns)
    if (node_of_.count(t) == 0) return false;
  const int g = static_cast<int>(groups_.size());
  groups_.push_back(group);
  for (int64_t t : group.t_ns) group_of_node_[static_cast<std::size_t>(node_of_.at(t))] = g;
  for (std::size_t l = 0; l < loops_.size(); ++l)
    if (group_of_node_[static_cast<std::size_t>(loop_nodes_[l].query)] == g) loop_nodes_[l].group = g;
  return true;
}

bool LoopGraphOptimizer::add_loop(const VerifiedLoop& loop) {
  const auto m = node_of_.find(loop.match_t_ns);
  const auto k = node_of_.find(loop.query_t_ns);
  if (m == node_of_.end() || k == node_of_.end() || m->second >= k->second) return false;
  loops_.push_back(loop);
  loop_nodes_.push_back(LoopNodes{m->second, k->second, group_of_node_[static_cast<std::size_t>(k->second)]});
  return true;
}

namespace {
RigidPose relative_of(const VerifiedLoop& l) { return RigidPose{l.p_mq, l.q_mq.normalized()}; }

/// 95 % quantile of a chi-square with k degrees of freedom (Wilson-Hilferty; within 1 % from k = 4 on).
double chi_square_quantile_95(int k) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + 1.6448536269514722 * std::sqrt(a);
  return k * c * c * c;
}

/// True when some group holding loops from index `first_new` on has none of its loops adopted.
bool rejects_a_new_group(const LoopGraphResult& r, std::size_t first_new, double min_weight) {
  std::vector<int> new_groups;
  for (std::size_t l = first_new; l < r.loops.size(); ++l)
    if (r.loops[l].group >= 0) new_groups.push_back(r.loops[l].group);
  std::sort(new_groups.begin(), new_groups.end());
  new_groups.erase(std::unique(new_groups.begin(), new_groups.end()), new_groups.end());
  for (int g : new_groups) {
    bool adopted = false;
    for (const LoopResult& l : r.loops) adopted = adopted || (l.group == g && l.used && l.weight >= min_weight);
    if (!adopted) return true;
  }
  return false;
}
}  // namespace

void LoopGraphOptimizer::warm_start(PoseGraph4Dof& graph, const LoopGraphResult& previous) const {
  const std::size_t n = previous.poses.size();
  if (n > odometry_.size() || previous.loops.size() > loops_.size())
    throw std::invalid_argument("LoopGraphOptimizer: the previous result is not of this graph");
  if (n == 0) return;
  for (std::size_t k = 0; k < n; ++k) graph.set_estimate(k, previous.poses[k]);
  // Keyframes added since: odometry moved by the last previous keyframe's correction (the drift then).
  const RigidPose drift = compose(previous.poses[n - 1], inverse(odometry_[n - 1]));
  for (std::size_t k = n; k < odometry_.size(); ++k) graph.set_estimate(k, compose(drift, odometry_[k]));
}

LoopGraphResult LoopGraphOptimizer::optimize(LoopMode mode, const LoopGraphResult* previous) const {
  LoopGraphResult result = optimize_from(previous, mode);
  if (previous != nullptr && rejects_a_new_group(result, previous->loops.size(), options_.adopted_min_weight)) {
    const int warm_iterations = result.solver_iterations;
    result = optimize_from(nullptr, mode);
    result.cold_restart = true;
    result.solver_iterations += warm_iterations;
  }
  if (mode == LoopMode::Dynavins && options_.skip_insignificant_correction) keep_odometry_if_consistent(result);
  return result;
}

void LoopGraphOptimizer::keep_odometry_if_consistent(LoopGraphResult& result) const {
  const PoseGraph4Dof at_odometry(odometry_, options_.graph);
  for (const LoopResult& r : result.loops) {
    if (!r.used || r.weight < options_.adopted_min_weight) continue;
    const LoopNodes& n = loop_nodes_[r.loop_index];
    result.odometry_chi2 +=
        at_odometry.loop_residual_sq(LoopEdge{n.match, n.query, relative_of(loops_[r.loop_index]), 1.0});
    ++result.adopted_loops;
  }
  if (result.adopted_loops == 0 || result.odometry_chi2 > chi_square_quantile_95(4 * result.adopted_loops)) return;
  result.poses = odometry_;
  result.correction_skipped = true;
  for (LoopResult& r : result.loops) r.used = false;
}

LoopGraphResult LoopGraphOptimizer::optimize_from(const LoopGraphResult* previous, LoopMode mode) const {
  PoseGraph4Dof graph(odometry_, options_.graph);
  if (previous != nullptr) warm_start(graph, *previous);
  if (mode == LoopMode::Dynavins) return optimize_dynavins(graph, previous);

  LoopGraphResult result;
  result.loops.resize(loops_.size());
  std::vector<LoopEdge> edges;
  for (std::size_t l = 0; l < loops_.size(); ++l) {
    result.loops[l].loop_index = l;
    result.loops[l].group = loop_nodes_[l].group;
    edges.push_back(LoopEdge{loop_nodes_[l].match, loop_nodes_[l].query, relative_of(loops_[l]), 1.0});
  }
  if (mode == LoopMode::All && !edges.empty()) {
    result.solver_iterations = graph.solve(edges, LoopEdgeLoss::Huber).iterations;  // VINS-Fusion: every loop, Huber
    for (LoopResult& r : result.loops) r.weight = 1.0, r.used = true;
    result.alternations = 1;
  } else if (mode == LoopMode::Switchable && !edges.empty()) {
    std::vector<double> s(edges.size(), 1.0);
    for (std::size_t l = 0; previous != nullptr && l < previous->loops.size(); ++l) s[l] = previous->loops[l].weight;
    result.solver_iterations = graph.solve(edges, LoopEdgeLoss::Switchable, &s).iterations;
    for (std::size_t l = 0; l < s.size(); ++l) result.loops[l].weight = s[l], result.loops[l].used = s[l] > 0.0;
    result.alternations = 1;
  }
  result.rounds = 1;
  result.poses = graph.poses();
  return result;
}

std::vector<LoopEdge> LoopGraphOptimizer::weighted_edges(const std::vector<GroupWeights>& state) const {
  std::vector<LoopEdge> edges;
  for (const GroupWeights& w : state) {
    // eq. 16: each loop residual of H^h scaled by w^h / |H^h| (inside the norm, so the cost has (w/|H|)^2).
    for (std::size_t l : w.h0)
      edges.push_back(LoopEdge{loop_nodes_[l].match, loop_nodes_[l].query, relative_of(loops_[l]),
                               w.w0 / static_cast<double>(w.h0.size())});
    for (std::size_t l : w.h1)
      edges.push_back(LoopEdge{loop_nodes_[l].match, loop_nodes_[l].query, relative_of(loops_[l]),
                               w.w1 / static_cast<double>(w.h1.size())});
  }
  return edges;
}

HypothesisWeights LoopGraphOptimizer::weight_step(const PoseGraph4Dof& graph, const GroupWeights& w) const {
  auto residual_sum = [&](const std::vector<std::size_t>& members) {  // R_h = sum ||r||^2_{P_L}
    double R = 0.0;
    for (std::size_t l : members)
      R += graph.loop_residual_sq(LoopEdge{loop_nodes_[l].match, loop_nodes_[l].query, relative_of(loops_[l]), 1.0});
    return R;
  };
  if (w.h0.empty()) return HypothesisWeights{};
  return solve_hypothesis_weights(residual_sum(w.h0), static_cast<int>(w.h0.size()), residual_sum(w.h1),
                                  static_cast<int>(w.h1.size()), options_.lambda_l);
}

LoopGraphResult LoopGraphOptimizer::optimize_dynavins(PoseGraph4Dof& graph, const LoopGraphResult* previous) const {
  LoopGraphResult result;
  result.loops.resize(loops_.size());
  for (std::size_t l = 0; l < loops_.size(); ++l) {
    result.loops[l].loop_index = l;
    result.loops[l].group = loop_nodes_[l].group;
  }
  const HypothesisClusterer clusterer(options_.clustering);

  // Loops per group (only loops whose query lies in a kept group take part, IV-A).
  std::vector<std::vector<std::size_t>> loops_of_group(groups_.size());
  for (std::size_t l = 0; l < loops_.size(); ++l)
    if (loop_nodes_[l].group >= 0) loops_of_group[static_cast<std::size_t>(loop_nodes_[l].group)].push_back(l);

  std::vector<GroupWeights> state;  // per active group
  bool settled = false;             // the last pose solve's weights are within the tolerance of state's
  for (int round = 0; round < std::max(1, options_.max_rounds); ++round) {
    // IV-B: (re-)cluster every group's loops with the current poses of the match keyframes.
    std::vector<GroupWeights> next;
    for (std::size_t g = 0; g < groups_.size(); ++g) {
      if (loops_of_group[g].empty()) continue;
      std::vector<GroupLoop> gl;
      for (std::size_t l : loops_of_group[g]) {
        const auto m = static_cast<std::size_t>(loop_nodes_[l].match);
        const auto k = static_cast<std::size_t>(loop_nodes_[l].query);
        gl.push_back(GroupLoop{l, graph.pose(m), relative_of(loops_[l]), odometry_[k]});
      }
      const int first = node_of_.at(groups_[g].first_t_ns());
      const GroupHypotheses h = clusterer.cluster(odometry_[static_cast<std::size_t>(first)], gl);
      GroupWeights w;
      w.group = static_cast<int>(g);
      if (!h.hypotheses.empty()) w.h0 = h.hypotheses[0].loop_indices;
      if (h.hypotheses.size() > 1) w.h1 = h.hypotheses[1].loop_indices;
      // First round: the poses are the drifted odometry, every loop looks wrong, so the alternation starts
      // with a pose step at weights summing to 1 (regulariser at its minimum), split evenly.
      w.w0 = w.h1.empty() ? 1.0 : 0.5;
      w.w1 = w.h1.empty() ? 0.0 : 0.5;
      next.push_back(std::move(w));
    }
    bool same = round > 0 && next.size() == state.size();
    for (std::size_t a = 0; same && a < next.size(); ++a) same = next[a].h0 == state[a].h0 && next[a].h1 == state[a].h1;
    if (same) break;
    // After the first round the poses are already corrected: a group starts from its previous weights
    // if its hypotheses are unchanged, else from a weight step at the current poses. Warm-started, the
    // first round keeps the previous optimisation's weights of unchanged groups (a group new since then
    // keeps the even split: its keyframes still carry the drift gathered since).
    const std::vector<GroupWeights>& carried = round == 0 && previous != nullptr ? previous->groups : state;
    for (std::size_t a = 0; a < next.size(); ++a) {
      if (round > 0) {
        const HypothesisWeights nw = weight_step(graph, next[a]);
        next[a].w0 = nw.w0, next[a].w1 = nw.w1;
      }
      for (const GroupWeights& old : carried)
        if (old.group == next[a].group && old.h0 == next[a].h0 && old.h1 == next[a].h1)
          next[a].w0 = old.w0, next[a].w1 = old.w1;
    }
    state = std::move(next);
    result.rounds = round + 1;

    settled = false;
    for (int it = 0; it < std::max(1, options_.max_alternations); ++it) {
      // Pose step with the weights fixed (the regulariser does not depend on the poses).
      result.solver_iterations += graph.solve(weighted_edges(state), LoopEdgeLoss::Plain).iterations;
      ++result.alternations;
      // Weight step with the poses fixed: closed form (hypothesis_weights.cpp).
      double max_change = 0.0;
      for (GroupWeights& w : state) {
        const HypothesisWeights nw = weight_step(graph, w);
        max_change = std::max({max_change, std::abs(nw.w0 - w.w0), std::abs(nw.w1 - w.w1)});
        w.w0 = nw.w0, w.w1 = nw.w1;
      }
      settled = max_change < options_.weight_tolerance;
      if (settled) break;
    }
  }
  // Final pose solve with the settled weights, so poses and reported weights belong together; not needed
  // when the last weight step moved no weight by more than the tolerance (the poses are already those).
  if (!settled) {
    result.solver_iterations += graph.solve(weighted_edges(state), LoopEdgeLoss::Plain).iterations;
    ++result.alternations;
  }
  for (const GroupWeights& w : state) {
    for (std::size_t l : w.h0)
      result.loops[l].hypothesis = 0, result.loops[l].weight = w.w0, result.loops[l].used = w.w0 > 0.0;
    for (std::size_t l : w.h1)
      result.loops[l].hypothesis = 1, result.loops[l].weight = w.w1, result.loops[l].used = w.w1 > 0.0;
  }
  result.groups = state;
  result.poses = graph.poses();
  return result;
}

}  // namespace dynavins::loop
