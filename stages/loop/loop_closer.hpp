#pragma once
// The loop-closure stage's logic as one plain object (paper IV; DESIGN.md §1-3), no threads, no LCM: fed
// the keyframes the estimator lets go, in time order, it
//   1. computes the keyframe's ORB descriptors and drops the image (only KeyframeDescriptors are kept),
//   2. groups keyframes on their tracked feature ids (IV-A, eq. 12, KeyframeGrouper),
//   3. turns the descriptors into a bag of words and asks the database for up to 3 older keyframes C_m,
//      with m < i (older than the first keyframe C_i of the current group, IV-B) and outside the most
//      recent keyframes,
//   4. verifies each candidate by PnP (LoopVerifier) and adds the verified loops to the pose graph,
//   5. when a group closes and loops were verified since the last optimisation (on a large graph, once
//      enough keyframes are new: min_new_keyframe_fraction), runs the selective
//      optimisation (LoopGraphOptimizer::optimize with the configured LoopMode) and keeps the corrected
//      poses. Loops count for LoopMode::Dynavins only once their group is closed (and kept), which is why
//      the trigger is the group's closing: the paper weighs the current group's hypotheses (IV-B, IV-C).
// finish() closes the last group and runs the final optimisation.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "messages/keyframe.hpp"
#include "stages/loop/graph/keyframe_grouper.hpp"
#include "stages/loop/graph/loop_graph_optimizer.hpp"
#include "stages/loop/graph/loop_mode.hpp"
#include "stages/loop/graph/rigid_pose.hpp"
#include "stages/loop/place/keyframe_database.hpp"
#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/loop_verifier.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"
#include "stages/loop/trajectory_correction.hpp"

namespace dynavins::loop {

struct LoopCloserOptions {
  LoopMode mode = LoopMode::Dynavins;  ///< off / all / switchable / dynavins (DESIGN.md §1 baselines)
  DescriptorOptions descriptors;
  LoopVerifierOptions verifier;
  KeyframeGrouperOptions grouping;  ///< alpha = 25, 8..20 keyframes per group
  LoopGraphOptions graph;
  int max_candidates = 3;            ///< database candidates verified per keyframe (IV-B: up to three m)
  double min_candidate_score = 0.0;  ///< L1 BoW score a candidate must exceed (PnP rejects the rest)
  /// Candidates must not be among the last N keyframes before the query (its own neighbourhood; VINS-Fusion
  /// skips the last 50 frames). The m < i rule of IV-B is applied on top of this.
  int exclude_recent_keyframes = 30;
  double min_candidate_age_s = 0.0;  ///< and at least this much older than the query (0: no time limit)
  /// Points whose robust-BA weight w_j (eq. 10) is below min_point_weight are probably on moving objects:
  /// when stored as a future loop candidate their 3-D points are not used for PnP (has_p_w cleared;
  /// descriptors still serve the bag of words and as query points).
  bool use_point_weights = true;
  float min_point_weight = 0.5f;
  /// Not in the paper: after a Dynavins optimisation, solve the pose graph once more from the odometry with
  /// the loops of the adopted hypotheses (final weight >= graph.adopted_min_weight) as plain unit-weight loop edges
  /// (Huber, as LoopMode::All) and every other loop left out. Eq. 16 scales each loop residual by w/|H|,
  /// so a group's |H| loops together pull like w^2/|H| of one loop edge; with the ~50 loops per group of
  /// a forward-moving camera (3 candidates per keyframe) the correction then stays partial (measured in
  /// tests/loop/test_loop_closer.cpp). The weights and hypotheses stay those of eq. 16. Off by default.
  bool refine_adopted = false;
  /// Each optimisation starts from the previous one's poses and weights (LoopGraphOptimizer::optimize's
  /// `previous`, which also says when it redoes one from the odometry), so its cost follows what is new,
  /// not the whole drift since the start (issue 22: from the odometry every time, a 30-minute run's
  /// optimisations took 4.1 s each at 6451 keyframes and the loop stage fell behind). false: every
  /// optimisation starts from the odometry.
  bool warm_start = true;
  /// Not in the paper: an optimisation also waits until this fraction of the graph's keyframes arrived
  /// since the previous one. A solve costs about linearly in the graph's size, so spacing them in
  /// proportion bounds the optimisation cost per keyframe on long runs (issue 22: with an optimisation
  /// at every group closing, 1.8 s each at up to 15621 keyframes, the 30-minute run fell to 0.4x real
  /// time). Below 8 / fraction keyframes (800 at 0.01) it never holds one back: a kept group has at least
  /// 8. The loop corrections then come up to that many keyframes later; finish() always optimises. 0: off.
  double min_new_keyframe_fraction = 0.01;
  /// Not in the paper: a keyframe whose loop an optimisation adopted (weight >= graph.adopted_min_weight)
  /// shows a place the database already holds. It leaves the database and its descriptors and points are
  /// dropped; it stays a pose-graph node. So on a route driven again and again the database grows with
  /// the places seen, not with time (issue 22: keeping every keyframe, 1.4 GB after 30 minutes). Later
  /// visits match the keyframes kept. Only adopted loops count: a keyframe whose loops were rejected
  /// (a moved object seen elsewhere) stays, so a genuine return there later still finds it. Irreversible:
  /// if a later optimisation rejects that loop after all, the place is still represented by the match.
  bool release_revisited = true;
};

/// A loop verified at this keyframe. The group index is known only once the group closes (kept groups);
/// the hypothesis only after an optimisation in LoopMode::Dynavins (see LoopCloserOutput::hypotheses).
struct NewLoop {
  VerifiedLoop loop;
  std::size_t loop_index = 0;     ///< index into LoopCloser::loops() (the optimizer's add_loop order)
  int64_t group_first_t_ns = -1;  ///< C_i of the (open) group the query belongs to
  double candidate_score = 0.0;   ///< BoW score of the match
  int matches = 0;                ///< putative descriptor matches
};

/// One group's hypotheses after an optimisation (for a loop_hypotheses_t message).
struct HypothesisReport {
  int group = -1;                   ///< index into LoopCloser::groups()
  int64_t group_first_t_ns = -1;    ///< C_i
  std::vector<std::size_t> h0, h1;  ///< loop indices of H^0, H^1
  double w0 = 0.0, w1 = 0.0;        ///< eq. 16 weights
};

struct LoopCloserTiming {
  double descriptors_ms = 0.0;   ///< compute_keyframe_descriptors (0 for add_descriptors)
  double query_ms = 0.0;         ///< bag of words + database query + insertion
  double verification_ms = 0.0;  ///< all candidates' PnP verification
  double optimization_ms = 0.0;  ///< the pose-graph optimisation, when it ran
};

struct LoopCloserOutput {
  int64_t t_ns = 0;                ///< the keyframe processed (finish(): the last keyframe)
  std::size_t keyframe_index = 0;  ///< its index in keyframe order
  int candidates = 0;              ///< database candidates verified
  std::vector<NewLoop> new_loops;  ///< loops verified at this keyframe
  bool group_closed = false;       ///< this keyframe (or finish) closed a group (kept or dropped)
  bool optimized = false;          ///< an optimisation ran
  /// When optimized: the corrected pose of every keyframe so far, in keyframe order (keyframe_t_ns).
  std::vector<int64_t> keyframe_t_ns;
  std::vector<RigidPose> corrected;
  /// Drift correction of the newest keyframe, T_corrected * T_odom^-1 (identity before the first
  /// optimisation): applied to later odometry poses (IMU-rate, window) it gives loop-corrected poses.
  RigidPose drift;
  /// When optimized in LoopMode::Dynavins: hypotheses and weights of the groups holding the loops verified
  /// since the previous optimisation (the current group's).
  std::vector<HypothesisReport> hypotheses;
  LoopCloserTiming timing;
};

class LoopCloser {
 public:
  /// `vocabulary` must not be null or empty (std::invalid_argument). `undistort` maps the extra corners'
  /// pixels to cam0's z = 1 plane (see compute_keyframe_descriptors; empty: they serve the BoW only).
  LoopCloser(std::shared_ptr<const VocabularyTree> vocabulary, const LoopCloserOptions& options = {},
             Undistort undistort = {});

  /// Processes one keyframe (t_ns strictly increasing, else std::invalid_argument). Nothing of the
  /// image is kept.
  LoopCloserOutput add_keyframe(const Keyframe& keyframe);
  /// The same from already computed descriptors (tests, or a caller that computed them elsewhere).
  LoopCloserOutput add_descriptors(KeyframeDescriptors descriptors);
  /// Closes the open group and runs the final optimisation (if the mode is not off and there are loops).
  LoopCloserOutput finish();

  std::size_t num_keyframes() const { return entries_.size(); }
  const std::vector<int64_t>& keyframe_t_ns() const { return t_ns_; }
  const std::vector<RigidPose>& odometry_poses() const { return odometry_; }
  /// Corrected keyframe poses: the last optimisation's, and drift * odometry for keyframes after it.
  const std::vector<RigidPose>& corrected_poses() const { return corrected_; }
  /// Per keyframe, T_corrected * T_odom^-1 (for correct_trajectory).
  std::vector<KeyframeCorrection> keyframe_corrections() const;
  const std::vector<VerifiedLoop>& loops() const { return optimizer_.loops(); }
  const std::vector<KeyframeGroup>& groups() const { return optimizer_.groups(); }
  const LoopGraphOptimizer& optimizer() const { return optimizer_; }
  /// The last optimisation's result (empty before the first); with optimizer() it gives loop_report().
  const LoopGraphResult& last_result() const { return last_result_; }
  int num_optimizations() const { return num_optimizations_; }
  const LoopCloserOptions& options() const { return options_; }

  /// Bytes held: per keyframe entry (descriptors, points), the database's index, the pose lists; no images.
  std::size_t memory_bytes() const;
  /// Keyframes taken out of the database as revisits (LoopCloserOptions::release_revisited).
  std::size_t num_released() const;
  /// Per keyframe (keyframe order): whether it was taken out of the database.
  const std::vector<bool>& released() const { return released_; }

 private:
  LoopCloserOutput process(KeyframeDescriptors d, double descriptors_ms);
  void run_optimization(LoopCloserOutput& out);
  std::vector<RigidPose> refine_with_adopted(const LoopGraphResult& result) const;
  void release_revisited(const LoopGraphResult& result);
  /// Index of a keyframe of this closer by its time (loops only join keyframes it holds).
  std::size_t keyframe_index(int64_t t_ns) const;

  std::shared_ptr<const VocabularyTree> vocabulary_;
  LoopCloserOptions options_;
  Undistort undistort_;
  LoopVerifier verifier_;
  KeyframeDatabase database_;
  KeyframeGrouper grouper_;
  LoopGraphOptimizer optimizer_;
  std::vector<KeyframeDescriptors> entries_;  // keyframe index -> what the database keeps
  std::vector<int64_t> t_ns_;
  std::vector<RigidPose> odometry_, corrected_;
  RigidPose drift_;
  LoopGraphResult last_result_;
  std::size_t loops_at_last_optimization_ = 0;
  std::size_t keyframes_at_last_optimization_ = 0;
  int num_optimizations_ = 0;
  std::vector<bool> released_;  // per keyframe: out of the database (release_revisited)
};

}  // namespace dynavins::loop
