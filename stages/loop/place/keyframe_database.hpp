#pragma once
// Inverted index of keyframes' bag-of-words vectors (paper IV; DBoW2's database): for each word, the
// keyframes containing it and their weights, so a query scores only keyframes sharing a word with it. The
// loop closer adds every keyframe and asks for the best-scoring older ones as loop candidates.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include "stages/loop/place/bow_vector.hpp"

namespace dynavins::loop {

struct DatabaseQueryOptions {
  int max_results = 3;                                     // a few candidates per query keyframe, best first
  double min_score = 0.0;                                  // candidates must score above this (L1 score, [0, 1])
  int64_t max_t_ns = std::numeric_limits<int64_t>::max();  // only keyframes with t_ns <= this
  int exclude_recent = 0;  // skip the most recently added N keyframes (the query's own neighbourhood)
};

struct PlaceCandidate {
  int64_t keyframe_id = 0;
  int64_t t_ns = 0;
  double score = 0.0;  // l1_score(query, keyframe)
};

class KeyframeDatabase {
 public:
  /// Adds a keyframe (ids need not be contiguous; adding an id twice throws std::invalid_argument).
  void add(int64_t keyframe_id, int64_t t_ns, const BowVector& bow);

  /// The keyframes allowed by `opts` that share a word with `bow`, highest score first (ties: older first).
  std::vector<PlaceCandidate> query(const BowVector& bow, const DatabaseQueryOptions& opts = {}) const;

  /// Takes a keyframe out of the candidates: its postings go, `bow` must be what it was added with
  /// (std::invalid_argument for an unknown id). Its id stays taken and it still counts for exclude_recent.
  void remove(int64_t keyframe_id, const BowVector& bow);

  std::size_t size() const { return entries_.size(); }  ///< keyframes added, removed ones included
  std::size_t num_postings() const { return num_postings_; }
  /// Bytes of the entries and the inverted index (capacities, hash buckets approximated).
  std::size_t memory_bytes() const;

 private:
  struct Entry {
    int64_t id, t_ns;
  };
  struct Posting {
    uint32_t entry;  // index into entries_ (insertion order)
    double weight;
  };
  std::vector<Entry> entries_;
  std::unordered_map<int64_t, uint32_t> index_of_id_;
  std::unordered_map<uint32_t, std::vector<Posting>> inverted_;  // word -> postings
  std::size_t num_postings_ = 0;
};

}  // namespace dynavins::loop
