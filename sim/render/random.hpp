#pragma once
// Deterministic hashing and random numbers for the simulator: same seed, same scene, on any machine and
// with any thread count (no std:: distributions, whose output differs between standard libraries).

#include <cmath>
#include <cstdint>

namespace dynavins::sim {

/// SplitMix64 finaliser: a well-mixed 64-bit hash of x.
inline uint64_t mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Hash of a key and two integers (lattice points, feature cells, rows).
inline uint64_t hash3(uint64_t key, int64_t i, int64_t j) {
  return mix64(mix64(key ^ mix64(static_cast<uint64_t>(i))) + static_cast<uint64_t>(j));
}

/// Uniform float in [0, 1) from a hash.
inline float hash_unit(uint64_t h) { return static_cast<float>(h >> 40) * (1.0f / 16777216.0f); }

/// Small deterministic generator (SplitMix64 stream) with the few distributions the scene needs.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(mix64(seed)) {}

  /// Next raw 64-bit value.
  uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return mix64(state_);
  }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Uniform integer in [lo, hi].
  int uniform_int(int lo, int hi) {
    return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1));
  }
  /// True with probability p.
  bool chance(double p) { return uniform() < p; }
  /// Standard normal (Box-Muller; one value per call keeps the stream simple).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  uint64_t state_;
};

}  // namespace dynavins::sim
