#include "pipeline/latency_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace dynavins::pipeline {

int LatencyHistogram::bin_of(int64_t ns) {
  const double us = std::max<double>(static_cast<double>(ns) / 1e3, 1.0);
  const int bin = static_cast<int>(std::floor(std::log2(us) * kBinsPerOctave));
  return std::clamp(bin, 0, kBins - 1);
}

double LatencyHistogram::bin_centre_ns(int bin) {
  return 1e3 * std::exp2((bin + 0.5) / kBinsPerOctave);
}

void LatencyHistogram::record(int64_t ns) {
  ns = std::max<int64_t>(ns, 0);
  bins_[bin_of(ns)].fetch_add(1, std::memory_order_relaxed);
  sum_ns_.fetch_add(ns, std::memory_order_relaxed);
  if (ns > max_ns_.load(std::memory_order_relaxed)) max_ns_.store(ns, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_release);
}

double LatencyHistogram::percentile_ms(double q) const {
  uint64_t total = 0;
  std::array<uint64_t, kBins> snap;
  for (int i = 0; i < kBins; ++i) total += (snap[i] = bins_[i].load(std::memory_order_relaxed));
  if (total == 0) return 0.0;
  const auto rank = static_cast<uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(total)));
  uint64_t seen = 0;
  const double max_ns = static_cast<double>(max_ns_.load(std::memory_order_relaxed));
  for (int i = 0; i < kBins; ++i) {
    seen += snap[i];
    if (seen >= std::max<uint64_t>(rank, 1)) return std::min(bin_centre_ns(i), max_ns) / 1e6;
  }
  return max_ns / 1e6;
}

LatencySummary LatencyHistogram::summary() const {
  LatencySummary s;
  s.count = count_.load(std::memory_order_acquire);
  if (s.count == 0) return s;
  s.mean_ms = static_cast<double>(sum_ns_.load(std::memory_order_relaxed)) / static_cast<double>(s.count) / 1e6;
  s.p50_ms = percentile_ms(0.50);
  s.p95_ms = percentile_ms(0.95);
  s.max_ms = static_cast<double>(max_ns_.load(std::memory_order_relaxed)) / 1e6;
  return s;
}

}  // namespace dynavins::pipeline
