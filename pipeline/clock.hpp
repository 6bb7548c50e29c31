#pragma once
#include <chrono>
#include <cstdint>

namespace dynavins::pipeline {

/// Monotonic time in nanoseconds, for latencies and pacing (never for sensor timestamps).
inline int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace dynavins::pipeline
