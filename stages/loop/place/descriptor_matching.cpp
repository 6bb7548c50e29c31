// Brute-force Hamming matching with ratio test and uniqueness (see descriptor_matching.hpp).
#include "stages/loop/place/descriptor_matching.hpp"

#include <cmath>
#include <limits>

#include "stages/loop/place/hamming.hpp"

namespace dynavins::loop {

std::vector<DescriptorMatch> match_descriptors(const KeyframeDescriptors& query, const KeyframeDescriptors& candidate,
                                               const DescriptorMatchOptions& opts) {
  std::vector<int> with_3d;
  for (int j = 0; j < static_cast<int>(candidate.points.size()) && j < candidate.descriptors.rows; ++j)
    if (candidate.points[j].has_p_w) with_3d.push_back(j);
  // best[j]: index into `out` of the query point currently holding candidate point j.
  std::vector<int> holder(candidate.points.size(), -1);
  std::vector<DescriptorMatch> out;
  std::vector<bool> alive;
  for (int i = 0; i < static_cast<int>(query.points.size()) && i < query.descriptors.rows; ++i) {
    if (!std::isfinite(query.points[i].xy.x()) || !std::isfinite(query.points[i].xy.y())) continue;
    const uint8_t* q = query.descriptors.ptr<uint8_t>(i);
    int best = std::numeric_limits<int>::max(), second = std::numeric_limits<int>::max(), best_j = -1;
    for (int j : with_3d) {
      const int d = hamming_distance(q, candidate.descriptors.ptr<uint8_t>(j));
      if (d < best) {
        second = best;
        best = d;
        best_j = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_j < 0 || best > opts.max_hamming) continue;
    if (second != std::numeric_limits<int>::max() && !(best < opts.ratio * second)) continue;
    const int h = holder[best_j];
    if (h >= 0) {
      if (out[h].distance <= best) continue;
      alive[h] = false;
    }
    holder[best_j] = static_cast<int>(out.size());
    out.push_back({i, best_j, best});
    alive.push_back(true);
  }
  std::vector<DescriptorMatch> kept;
  kept.reserve(out.size());
  for (std::size_t k = 0; k < out.size(); ++k)
    if (alive[k]) kept.push_back(out[k]);
  return kept;
}

}  // namespace dynavins::loop
