#pragma once
// Lock-free latency recorder: one writer thread (the stage), any number of readers (stats, publisher).
// Log-spaced bins, 8 per octave from 1 us, so a reported percentile is within ~4.5% of the true value.

#include <array>
#include <atomic>
#include <cstdint>

namespace dynavins::pipeline {

struct LatencySummary {
  uint64_t count = 0;
  double mean_ms = 0.0;
  double p50_ms = 0.0;
  double p95_ms = 0.0;
  double max_ms = 0.0;
};

class LatencyHistogram {
 public:
  static constexpr int kBinsPerOctave = 8;
  static constexpr int kOctaves = 36;  // 1 us .. ~19 h
  static constexpr int kBins = kBinsPerOctave * kOctaves;

  /// Records one duration. Called by the single writer only.
  void record(int64_t ns);
  /// Consistent-enough snapshot for reporting; safe from any thread.
  LatencySummary summary() const;
  /// Percentile q in [0, 1] in milliseconds (geometric centre of its bin, clamped to the max seen).
  double percentile_ms(double q) const;

 private:
  static int bin_of(int64_t ns);
  static double bin_centre_ns(int bin);

  std::array<std::atomic<uint64_t>, kBins> bins_{};
  std::atomic<uint64_t> count_{0};
  std::atomic<int64_t> sum_ns_{0};
  std::atomic<int64_t> max_ns_{0};
};

}  // namespace dynavins::pipeline
