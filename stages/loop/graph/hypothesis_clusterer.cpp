// Multiple-hypothesis clustering, paper IV-B eq. 13-14 (see hypothesis_clusterer.hpp).
#include "stages/loop/graph/hypothesis_clusterer.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dynavins::loop {

RigidPose loop_query_pose(const RigidPose& T_W_m, const RigidPose& T_m_k) {
  return compose(T_W_m, T_m_k);  // eq. 13 (paper: _mT_W^k = T_m^k . T_W^m)
}

RigidPose loop_group_start_pose(const RigidPose& T_W_m, const RigidPose& T_m_k, const RigidPose& T_W_k_odom,
                                const RigidPose& T_W_i_odom) {
  const RigidPose T_k_i = compose(inverse(T_W_k_odom), T_W_i_odom);  // local relative pose, odometry
  return compose(loop_query_pose(T_W_m, T_m_k), T_k_i);              // eq. 14 (paper: T_k^i . _mT_W^k)
}

bool estimates_agree(const RigidPose& a, const RigidPose& b, const HypothesisClustererOptions& options) {
  const double dt = (a.p - b.p).norm();
  const double dyaw = std::abs(normalize_angle(yaw_of(a.q) - yaw_of(b.q)));
  return dt <= options.max_translation_m && dyaw <= options.max_yaw_rad;
}

GroupHypotheses HypothesisClusterer::cluster(const RigidPose& T_W_i_odom, const std::vector<GroupLoop>& loops) const {
  GroupHypotheses out;
  const std::size_t n = loops.size();
  out.estimates.reserve(n);
  for (const GroupLoop& l : loops)
    out.estimates.push_back(loop_group_start_pose(l.T_W_m, l.T_m_k, l.T_W_k_odom, T_W_i_odom));

  std::vector<std::vector<char>> agree(n, std::vector<char>(n, 0));
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) agree[a][b] = estimates_agree(out.estimates[a], out.estimates[b], options_);

  // Greedy neighbourhood clustering (see the header).
  std::vector<int> raw_cluster(n, -1);
  std::vector<std::vector<std::size_t>> clusters;
  for (;;) {
    int best = -1;
    std::size_t best_count = 0;
    for (std::size_t a = 0; a < n; ++a) {
      if (raw_cluster[a] >= 0) continue;
      std::size_t count = 0;
      for (std::size_t b = 0; b < n; ++b) count += (raw_cluster[b] < 0 && agree[a][b]) ? 1 : 0;
      if (count > best_count) best = static_cast<int>(a), best_count = count;
    }
    if (best < 0) break;
    std::vector<std::size_t> members;
    for (std::size_t b = 0; b < n; ++b)
      if (raw_cluster[b] < 0 && agree[static_cast<std::size_t>(best)][b]) members.push_back(b);
    for (std::size_t b : members) raw_cluster[b] = static_cast<int>(clusters.size());
    clusters.push_back(std::move(members));
  }

  // Order by cardinality (stable: equal sizes keep the order they were formed in), keep the top ones.
  std::vector<std::size_t> order(clusters.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return clusters[a].size() > clusters[b].size(); });
  std::vector<int> rank(clusters.size());
  for (std::size_t r = 0; r < order.size(); ++r) rank[order[r]] = static_cast<int>(r);
  out.cluster_of.resize(n);
  for (std::size_t a = 0; a < n; ++a) out.cluster_of[a] = rank[static_cast<std::size_t>(raw_cluster[a])];

  const std::size_t keep = std::min(order.size(), static_cast<std::size_t>(std::max(0, options_.max_hypotheses)));
  for (std::size_t r = 0; r < keep; ++r) {
    std::vector<std::size_t> members = clusters[order[r]];
    std::sort(members.begin(), members.end());
    LoopHypothesis h;
    Eigen::Vector3d p_sum = Eigen::Vector3d::Zero();
    double s = 0.0, c = 0.0;
    for (std::size_t a : members) {
      h.loop_indices.push_back(loops[a].loop_index);
      p_sum += out.estimates[a].p;
      const double yaw = yaw_of(out.estimates[a].q);
      s += std::sin(yaw), c += std::cos(yaw);
    }
    const RigidPose& first = out.estimates[members.front()];
    h.T_W_i.p = p_sum / static_cast<double>(members.size());
    h.T_W_i.q = quat_from_ypr(std::atan2(s, c), pitch_of(first.q), roll_of(first.q));
    out.hypotheses.push_back(std::move(h));
  }
  return out;
}

}  // namespace dynavins::loop
