#pragma once
// Data-parallel loop over image rows for texture painting: rows [0, rows) are cut into one
// contiguous band per hardware thread and `body(range)` runs on each (the calling thread takes the
// first band). std::thread rather than cv::parallel_for_: Debian's OpenCV runs the latter on TBB,
// whose synchronisation ThreadSanitizer cannot see. Every row must be a pure function of its index,
// so the result does not depend on the split.

#include <algorithm>
#include <thread>
#include <vector>

#include <opencv2/core/types.hpp>

namespace dynavins::sim {

template <typename Body>
void parallel_rows(int rows, const Body& body) {
  const int bands = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, std::max(rows, 1));
  std::vector<std::thread> helpers;
  helpers.reserve(static_cast<std::size_t>(bands - 1));
  for (int b = 1; b < bands; ++b)
    helpers.emplace_back([&body, b, bands, rows] { body(cv::Range(rows * b / bands, rows * (b + 1) / bands)); });
  body(cv::Range(0, rows / bands));
  for (auto& t : helpers) t.join();
}

}  // namespace dynavins::sim
