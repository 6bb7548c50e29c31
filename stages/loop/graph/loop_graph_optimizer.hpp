#pragma once
// The selective global optimisation of paper IV as one object: keyframe nodes (odometry poses), keyframe
// groups (eq. 12), verified loops; optimize(mode) runs the 4-DoF pose graph with the chosen loop handling
// and returns the corrected poses and what became of every loop. In LoopMode::Dynavins it alternates, per
// round, the closed-form hypothesis weight step (eq. 16-17) and the pose solve with the weights fixed,
// then re-clusters every group's loops with the new poses (IV-C, last paragraph) for the next round.

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "messages/keyframe.hpp"
#include "stages/loop/graph/hypothesis_clusterer.hpp"
#include "stages/loop/graph/hypothesis_weights.hpp"
#include "stages/loop/graph/keyframe_grouper.hpp"
#include "stages/loop/graph/loop_mode.hpp"
#include "stages/loop/graph/pose_graph_4dof.hpp"
#include "stages/loop/graph/rigid_pose.hpp"

namespace dynavins::loop {

struct LoopGraphOptions {
  HypothesisClustererOptions clustering;
  PoseGraphOptions graph;
  double lambda_l = 1.0;           ///< eq. 16 (DESIGN.md §1)
  int max_alternations = 10;       ///< weight step + pose solve pairs per round
  double weight_tolerance = 1e-3;  ///< the alternation stops when no weight moves more than this
  int max_rounds = 3;              ///< re-clusterings; stops early when the hypotheses no longer change
  /// A loop counts as adopted at weight >= this (the warm start's cold restart, see optimize(); and
  /// LoopCloserOptions::refine_adopted).
  double adopted_min_weight = 0.5;
  /// Not in the paper (LoopMode::Dynavins only): when the odometry already agrees with every adopted loop
  /// within the loop edges' stated uncertainty (P_L), the correction is not applied and the odometry is
  /// the answer. Test: the whitened squared residuals of the adopted loops at the odometry poses, summed,
  /// below the 95 % quantile of a chi-square with 4 per loop degrees of freedom. Such loops carry no
  /// correction the graph can tell from their own error, only that error: on `e_shape` (odometry at
  /// ~2 cm, adopted loops 2-9 cm off) applying them made the trajectory 1.5x worse than the odometry on
  /// four noise draws out of four. The weights and hypotheses are still solved and reported.
  bool skip_insignificant_correction = true;
};

/// What became of one loop (for loops.csv).
struct LoopResult {
  std::size_t loop_index = 0;  ///< order of add_loop
  int group = -1;              ///< index into groups() of the group holding the query, -1 if none
  int hypothesis = -1;         ///< 0 or 1 (H^0, H^1) in LoopMode::Dynavins; -1 if outside the top two / other modes
  double weight = 0.0;         ///< all: 1; switchable: s; dynavins: w^h of its hypothesis (0 if unused); off: 0
  bool used = false;           ///< the loop entered the last pose solve with a non-zero weight
};

/// Per group and round, the hypotheses and their final weights (Dynavins only).
struct GroupWeights {
  int group = -1;
  std::vector<std::size_t> h0, h1;  ///< loop indices of H^0, H^1
  double w0 = 0.0, w1 = 0.0;
};

struct LoopGraphResult {
  std::vector<RigidPose> poses;  ///< corrected T_W^k per keyframe, in add_keyframe order
  std::vector<LoopResult> loops;
  std::vector<GroupWeights> groups;  ///< last round's hypotheses and weights (Dynavins), groups with loops
  int rounds = 0;
  int alternations = 0;  ///< total pose solves
  int solver_iterations = 0;  ///< Ceres iterations of all pose solves (with a cold restart: of both tries)
  bool cold_restart = false;  ///< warm-started, then redone from the odometry (see optimize())
  /// LoopGraphOptions::skip_insignificant_correction applied: poses are the odometry, no loop is `used`.
  bool correction_skipped = false;
  double odometry_chi2 = 0.0;  ///< the test's statistic (sum over the adopted loops at the odometry)
  int adopted_loops = 0;       ///< loops it summed over
};

class LoopGraphOptimizer {
 public:
  explicit LoopGraphOptimizer(const LoopGraphOptions& options = {});

  /// Keyframes in time order with their odometry pose T_W^k.
  void add_keyframe(int64_t t_ns, const RigidPose& T_W_k_odom);
  /// A kept group (KeyframeGrouper output); members must be known keyframes. Returns false otherwise.
  bool add_group(const KeyframeGroup& group);
  /// A verified loop between two known keyframes (match older than query). Returns false otherwise.
  bool add_loop(const VerifiedLoop& loop);

  std::size_t num_keyframes() const { return odometry_.size(); }
  const std::vector<KeyframeGroup>& groups() const { return groups_; }
  const std::vector<VerifiedLoop>& loops() const { return loops_; }

  /// Runs the pose graph. Without `previous` it starts from the odometry. With `previous` (an earlier
  /// optimize() result of this graph, in the same mode) it starts where that one ended: its poses, and
  /// for keyframes added since, the odometry moved by the newest previous keyframe's correction; its
  /// switch values (switchable) or the weights of every group whose hypotheses are unchanged (dynavins).
  /// The incremental use of a growing graph: each solve then only absorbs what is new, in a few
  /// iterations instead of re-solving the whole drift (VINS-Fusion's pose graph also starts from its last
  /// estimate). A warm start can keep an earlier wrong choice: a false hypothesis adopted when it was the
  /// only evidence bends the graph so that later true loops look wrong (measured in bench_pose_graph
  /// --incremental). So when a group holding loops new since `previous` ends with none of its loops
  /// adopted (weight >= adopted_min_weight), the optimisation is redone from the odometry and that result
  /// returned, with cold_restart set. Throws std::invalid_argument if `previous` holds more poses or
  /// loops than the graph.
  LoopGraphResult optimize(LoopMode mode, const LoopGraphResult* previous = nullptr) const;

 private:
  struct LoopNodes {
    int match = 0, query = 0, group = -1;
  };
  LoopGraphResult optimize_from(const LoopGraphResult* previous, LoopMode mode) const;
  LoopGraphResult optimize_dynavins(PoseGraph4Dof& graph, const LoopGraphResult* previous) const;
  void warm_start(PoseGraph4Dof& graph, const LoopGraphResult& previous) const;
  void keep_odometry_if_consistent(LoopGraphResult& result) const;
  std::vector<LoopEdge> weighted_edges(const std::vector<GroupWeights>& state) const;
  HypothesisWeights weight_step(const PoseGraph4Dof& graph, const GroupWeights& w) const;

  LoopGraphOptions options_;
  std::vector<int64_t> t_ns_;
  std::vector<RigidPose> odometry_;
  std::unordered_map<int64_t, int> node_of_;
  std::vector<KeyframeGroup> groups_;
  std::vector<int> group_of_node_;
  std::vector<VerifiedLoop> loops_;
  std::vector<LoopNodes> loop_nodes_;
};

}  // namespace dynavins::loop
