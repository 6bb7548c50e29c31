#pragma once
// Putative 2-D/3-D correspondences between a query keyframe and a loop candidate by brute-force Hamming
// matching of their ORB descriptors (ratio test and a distance cap, one query point per candidate point);
// the input of the PnP verification.

#include <vector>

#include "stages/loop/place/keyframe_descriptors.hpp"

namespace dynavins::loop {

struct DescriptorMatchOptions {
  int max_hamming = 50;  // of 256 bits; ORB's usual acceptance distance
  double ratio = 0.8;    // best < ratio * second best (Lowe's test), when there is a second
};

struct DescriptorMatch {
  int query = 0;  // index into the query's points
  int match = 0;  // index into the candidate's points
  int distance = 0;
};

/// Matches every query point with finite xy against the candidate's points that have a 3-D point
/// (has_p_w). When several query points pick the same candidate point, only the closest is kept.
std::vector<DescriptorMatch> match_descriptors(const KeyframeDescriptors& query, const KeyframeDescriptors& candidate,
                                               const DescriptorMatchOptions& opts = {});

}  // namespace dynavins::loop
