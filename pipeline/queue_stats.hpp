#pragma once
// What every queue reports: depth, bound, traffic and drops (DESIGN.md §2, "every stage reports").

#include <atomic>
#include <cstdint>
#include <string>

namespace dynavins::pipeline {

/// How a producer is treated when the queue is full (DESIGN.md §2).
enum class Backpressure {
  Block,       ///< producer waits: lossless and repeatable (replay at full speed)
  DropOldest,  ///< SPSC frames in real time: the consumer takes the newest waiting item, older ones are dropped
  DropNewest,  ///< fan-in in real time: an item that finds the queue full is dropped
};

const char* to_string(Backpressure policy);

struct QueueStats {
  std::string name;
  std::size_t capacity = 0;
  std::size_t depth = 0;      ///< items waiting now (approximate while running)
  std::size_t max_depth = 0;  ///< high-water mark
  // Every item offered to push() ends delivered or dropped: after a drain, pushed == delivered + dropped.
  uint64_t pushed = 0;     ///< items offered by the producer
  uint64_t delivered = 0;  ///< items handed to the consumer
  uint64_t dropped = 0;    ///< items lost to back-pressure (never in Block mode)
};

/// Counters a queue updates as it runs; readable from any thread.
struct QueueCounters {
  std::atomic<uint64_t> pushed{0};
  std::atomic<uint64_t> delivered{0};
  std::atomic<uint64_t> dropped{0};
  std::atomic<std::size_t> max_depth{0};

  void note_depth(std::size_t depth) {
    std::size_t seen = max_depth.load(std::memory_order_relaxed);
    while (depth > seen && !max_depth.compare_exchange_weak(seen, depth, std::memory_order_relaxed)) {
    }
  }
};

/// Type-erased view of a queue for reporting and for closing from the wiring.
class QueueBase {
 public:
  virtual ~QueueBase() = default;
  virtual QueueStats stats() const = 0;
  virtual const std::string& name() const = 0;
};

}  // namespace dynavins::pipeline
