#pragma once
// A bag-of-words vector: sparse (word id, weight) pairs sorted by word, L1-normalised, and the L1 similarity
// score of DBoW2 (Galvez-Lopez and Tardos 2012, eq. 2): s(v, w) = 1 - 1/2 |v/|v| - w/|w||_1, in [0, 1].

#include <cstdint>
#include <vector>

namespace dynavins::loop {

struct BowEntry {
  uint32_t word = 0;
  double weight = 0.0;
  bool operator==(const BowEntry& o) const { return word == o.word && weight == o.weight; }
};

/// Sorted by word, no duplicates, weights summing to 1 (empty for an image without descriptors).
using BowVector = std::vector<BowEntry>;

/// L1 score of two L1-normalised vectors: 1/2 sum over common words of (|v_i| + |w_i| - |v_i - w_i|),
/// which equals 1 - 1/2 |v - w|_1 when both sum to 1. 1 for identical vectors, 0 for disjoint ones.
double l1_score(const BowVector& v, const BowVector& w);

/// The score of one common word, the term l1_score sums (the inverted index sums it per entry).
inline double l1_term(double vi, double wi) {
  const double a = vi < 0 ? -vi : vi, b = wi < 0 ? -wi : wi, d = vi - wi;
  return 0.5 * (a + b - (d < 0 ? -d : d));
}

}  // namespace dynavins::loop
