#pragma once
// Hamming distance between two 256-bit binary descriptors (ORB, 32 bytes): the metric of the
// descriptor matching and of the vocabulary tree's binary k-medians. Header-only, one popcount per word.

#include <cstdint>
#include <cstring>

namespace dynavins::loop {

/// Bytes of one binary descriptor (ORB's 256 bits).
constexpr int kDescriptorBytes = 32;

/// Number of differing bits between the 32-byte descriptors at `a` and `b`.
inline int hamming_distance(const uint8_t* a, const uint8_t* b) {
  int d = 0;
  for (int i = 0; i < kDescriptorBytes; i += 8) {
    uint64_t x = 0, y = 0;
    std::memcpy(&x, a + i, 8);
    std::memcpy(&y, b + i, 8);
    d += __builtin_popcountll(x ^ y);
  }
  return d;
}

}  // namespace dynavins::loop
