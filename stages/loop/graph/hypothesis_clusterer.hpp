#pragma once
// Multiple-hypothesis clustering of a group's verified loops (paper IV-B, eq. 13-14). Each loop (C_k in
// the group matched to an older C_m) gives an estimate of the pose of the group's first keyframe C_i;
// loops whose features belong to the same (static or relocated) object give estimates that agree, so the
// estimates are clustered by distance and the two largest clusters become the hypotheses H^0, H^1 that
// the selective pose graph weighs as a whole (IV-C).

#include <cstddef>
#include <vector>

#include "stages/loop/graph/rigid_pose.hpp"

namespace dynavins::loop {

struct HypothesisClustererOptions {
  double max_translation_m = 0.5;                              ///< two estimates agree within this distance ...
  double max_yaw_rad = 10.0 * 3.14159265358979323846 / 180.0;  ///< ... and this yaw difference (DESIGN.md §1)
  int max_hypotheses = 2;                                      ///< top-two clusters by cardinality (IV-B)
};

/// One loop of a group, as the clusterer needs it.
struct GroupLoop {
  std::size_t loop_index = 0;  ///< the caller's id of the loop, reported back in the hypotheses
  RigidPose T_W_m;             ///< match keyframe C_m in the world: the pose graph's current estimate
  RigidPose T_m_k;             ///< verified relative pose: query C_k in C_m's frame (VerifiedLoop)
  RigidPose T_W_k_odom;        ///< query keyframe C_k in the world, odometry
};

/// One hypothesis: the loops of one cluster and the mean of their estimates of T_W^i.
struct LoopHypothesis {
  std::vector<std::size_t> loop_indices;  ///< GroupLoop::loop_index of the members, in input order
  RigidPose T_W_i;  ///< mean estimate (mean translation, circular-mean yaw, first member's roll/pitch)
};

struct GroupHypotheses {
  std::vector<LoopHypothesis> hypotheses;  ///< H^0 (largest), H^1; at most max_hypotheses, possibly empty
  std::vector<RigidPose> estimates;        ///< _{k,m}T_W^i of every input loop, in input order
  std::vector<int> cluster_of;             ///< cluster id per input loop (0, 1 are H^0, H^1; higher ones dropped)
};

/// eq. 13: _mT_W^k = T_W^m * T_m^k, the query's world pose as the loop sees it.
RigidPose loop_query_pose(const RigidPose& T_W_m, const RigidPose& T_m_k);

/// eq. 14: _{k,m}T_W^i = _mT_W^k * T_k^i with the local relative pose from odometry,
/// T_k^i = (T_W^k_odom)^-1 * T_W^i_odom.
RigidPose loop_group_start_pose(const RigidPose& T_W_m, const RigidPose& T_m_k, const RigidPose& T_W_k_odom,
                                const RigidPose& T_W_i_odom);

/// True if two pose estimates agree within the options' translation and yaw thresholds.
bool estimates_agree(const RigidPose& a, const RigidPose& b, const HypothesisClustererOptions& options);

/// Clusters a group's loops into hypotheses. The clustering is greedy on neighbourhoods: the estimate
/// that agrees with the most still-unassigned estimates seeds a cluster made of itself and those
/// neighbours; repeat until every estimate is assigned (ties go to the earlier loop, so the result is
/// deterministic). Clusters are then ordered by size (stable), and the first max_hypotheses kept.
class HypothesisClusterer {
 public:
  explicit HypothesisClusterer(const HypothesisClustererOptions& options = {}) : options_(options) {}

  GroupHypotheses cluster(const RigidPose& T_W_i_odom, const std::vector<GroupLoop>& loops) const;

  const HypothesisClustererOptions& options() const { return options_; }

 private:
  HypothesisClustererOptions options_;
};

}  // namespace dynavins::loop
