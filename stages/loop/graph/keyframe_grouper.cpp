// Keyframe grouping, paper IV-A eq. 12 (see keyframe_grouper.hpp).
#include "stages/loop/graph/keyframe_grouper.hpp"

#include <algorithm>
#include <iterator>
#include <utility>

namespace dynavins::loop {

namespace {
std::vector<int64_t> sorted_unique(std::vector<int64_t> ids) {
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}
}  // namespace

std::vector<int64_t> tracked_feature_ids(const Keyframe& kf) {
  std::vector<int64_t> ids;
  ids.reserve(kf.points.size());
  for (const KeyframePoint& pt : kf.points)
    if (pt.id >= 0) ids.push_back(pt.id);
  return sorted_unique(std::move(ids));
}

KeyframeGrouper::KeyframeGrouper(const KeyframeGrouperOptions& options) : options_(options) {}

std::optional<KeyframeGroup> KeyframeGrouper::add_keyframe(int64_t t_ns, const std::vector<int64_t>& feature_ids) {
  std::vector<int64_t> ids = sorted_unique(feature_ids);
  if (!open_.t_ns.empty()) {
    // F_i^k = F_i^{k-1} ∩ ids(C_k): a feature counts only if it was tracked through every keyframe since C_i.
    std::vector<int64_t> shared;
    std::set_intersection(shared_.begin(), shared_.end(), ids.begin(), ids.end(), std::back_inserter(shared));
    const bool full = static_cast<int>(open_.t_ns.size()) >= options_.max_group_size;
    if (!full && static_cast<int>(shared.size()) >= options_.min_shared_features) {  // eq. 12: |F_i^k| >= alpha
      open_.t_ns.push_back(t_ns);
      shared_ = std::move(shared);
      return std::nullopt;
    }
  }
  std::optional<KeyframeGroup> closed = close_open_group(options_.min_group_size);
  open_.t_ns.assign(1, t_ns);  // C_k starts the next group: F_k^k = ids(C_k)
  shared_ = std::move(ids);
  return closed;
}

std::optional<KeyframeGroup> KeyframeGrouper::finish() {
  std::optional<KeyframeGroup> closed = close_open_group(options_.keep_last_group ? 1 : options_.min_group_size);
  open_.t_ns.clear();
  shared_.clear();
  return closed;
}

std::optional<KeyframeGroup> KeyframeGrouper::close_open_group(int min_size) {
  if (open_.t_ns.empty()) return std::nullopt;
  if (static_cast<int>(open_.t_ns.size()) < min_size) {
    ++num_dropped_;
    return std::nullopt;
  }
  groups_.push_back(open_);
  return open_;
}

}  // namespace dynavins::loop
