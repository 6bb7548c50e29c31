// Inverted-index scoring: the L1 score summed word by word over the shared words (see keyframe_database.hpp).
#include "stages/loop/place/keyframe_database.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace dynavins::loop {

void KeyframeDatabase::add(int64_t keyframe_id, int64_t t_ns, const BowVector& bow) {
  const auto entry = static_cast<uint32_t>(entries_.size());
  if (!index_of_id_.emplace(keyframe_id, entry).second)
    throw std::invalid_argument("KeyframeDatabase::add: keyframe " + std::to_string(keyframe_id) + " already added");
  entries_.push_back({keyframe_id, t_ns});
  for (const BowEntry& e : bow) inverted_[e.word].push_back({entry, e.weight});
  num_postings_ += bow.size();
}

void KeyframeDatabase::remove(int64_t keyframe_id, const BowVector& bow) {
  const auto found = index_of_id_.find(keyframe_id);
  if (found == index_of_id_.end())
    throw std::invalid_argument("KeyframeDatabase::remove: keyframe " + std::to_string(keyframe_id) + " was not added");
  const uint32_t entry = found->second;
  for (const BowEntry& e : bow) {
    const auto it = inverted_.find(e.word);
    if (it == inverted_.end()) continue;
    std::vector<Posting>& postings = it->second;
    const auto end =
        std::remove_if(postings.begin(), postings.end(), [&](const Posting& p) { return p.entry == entry; });
    num_postings_ -= static_cast<std::size_t>(postings.end() - end);
    postings.erase(end, postings.end());
    if (postings.empty()) inverted_.erase(it);
    else if (postings.size() < postings.capacity() / 4) postings.shrink_to_fit();  // memory follows the places kept
  }
}

std::size_t KeyframeDatabase::memory_bytes() const {
  // Hash nodes: key, value and about two pointers each (libstdc++'s node plus its bucket).
  std::size_t b = sizeof(*this) + entries_.capacity() * sizeof(Entry) +
                  index_of_id_.size() * (sizeof(int64_t) + sizeof(uint32_t) + 2 * sizeof(void*));
  for (const auto& [word, postings] : inverted_)
    b += sizeof(word) + sizeof(postings) + 2 * sizeof(void*) + postings.capacity() * sizeof(Posting);
  return b;
}

std::vector<PlaceCandidate> KeyframeDatabase::query(const BowVector& bow, const DatabaseQueryOptions& opts) const {
  const std::size_t n = entries_.size();
  const std::size_t allowed_end =
      opts.exclude_recent > 0 ? (n > static_cast<std::size_t>(opts.exclude_recent) ? n - opts.exclude_recent : 0) : n;
  std::vector<double> score(allowed_end, 0.0);
  std::vector<bool> touched(allowed_end, false);
  for (const BowEntry& q : bow) {
    auto it = inverted_.find(q.word);
    if (it == inverted_.end()) continue;
    for (const Posting& p : it->second) {
      if (p.entry >= allowed_end || entries_[p.entry].t_ns > opts.max_t_ns) continue;
      score[p.entry] += l1_term(q.weight, p.weight);  // DBoW2 L1 score, word by word
      touched[p.entry] = true;
    }
  }
  std::vector<PlaceCandidate> out;
  for (std::size_t i = 0; i < allowed_end; ++i)
    if (touched[i] && score[i] > opts.min_score) out.push_back({entries_[i].id, entries_[i].t_ns, score[i]});
  std::stable_sort(out.begin(), out.end(),
                   [](const PlaceCandidate& a, const PlaceCandidate& b) { return a.score > b.score; });
  if (opts.max_results >= 0 && out.size() > static_cast<std::size_t>(opts.max_results)) out.resize(opts.max_results);
  return out;
}

}  // namespace dynavins::loop
