#pragma once
// Read-mostly snapshot handed from one writer thread to one reader thread without locks:
// a triple buffer. The writer fills its private slot and swaps it in; the reader swaps the
// freshest slot out. Neither ever waits, and the reader always sees a whole, consistent value.
// Used for the estimator's "latest state" that the IMU stage propagates (DESIGN.md §2).

#include <array>
#include <atomic>
#include <cstdint>
#include <optional>

namespace dynavins::pipeline {

template <typename T>
class LatestValue {
 public:
  /// Writer thread only: publish a new value.
  void write(const T& value) {
    slots_[back_] = value;
    const uint8_t old = middle_.exchange(static_cast<uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndexMask;
  }

  /// Reader thread only: the newest value written so far, or nothing if none was written yet.
  std::optional<T> read() {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = old & kIndexMask;
      has_value_ = true;
    }
    if (!has_value_) return std::nullopt;
    return slots_[front_];
  }

 private:
  static constexpr uint8_t kFresh = 0x4;
  static constexpr uint8_t kIndexMask = 0x3;

  std::array<T, 3> slots_{};
  std::atomic<uint8_t> middle_{1};
  uint8_t back_ = 0;   // writer-owned
  uint8_t front_ = 2;  // reader-owned
  bool has_value_ = false;  // reader-owned
};

}  // namespace dynavins::pipeline
