#include <catch2/catch.hpp>

#include "pipeline/latency_histogram.hpp"

using dynavins::pipeline::LatencyHistogram;

TEST_CASE("LatencyHistogram: exact mean and max, percentiles within a bin", "[latency]") {
  LatencyHistogram h;
  CHECK(h.summary().count == 0);
  // 1..1000 ms, uniform: p50 = 500 ms, p95 = 950 ms.
  for (int ms = 1; ms <= 1000; ++ms) h.record(static_cast<int64_t>(ms) * 1'000'000);
  const auto s = h.summary();
  CHECK(s.count == 1000);
  CHECK(s.mean_ms == Approx(500.5).epsilon(1e-9));
  CHECK(s.max_ms == Approx(1000.0));
  CHECK(s.p50_ms == Approx(500.0).epsilon(0.05));
  CHECK(s.p95_ms == Approx(950.0).epsilon(0.05));
}

TEST_CASE("LatencyHistogram: sub-microsecond and huge values are clamped into range", "[latency]") {
  LatencyHistogram h;
  h.record(0);
  h.record(-5);
  h.record(int64_t{1} << 62);
  CHECK(h.summary().count == 3);
  CHECK(h.percentile_ms(0.0) >= 0.0);
  CHECK(h.percentile_ms(1.0) <= h.summary().max_ms);
}
