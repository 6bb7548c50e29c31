#pragma once
// Bounded single-producer single-consumer link between two stage threads, over moodycamel's
// BlockingReaderWriterCircularBuffer (lock-free, fixed capacity). No mutex anywhere.
//
// Back-pressure (DESIGN.md §2):
//  - Block: push() waits while the queue is full; nothing is lost, runs are repeatable.
//  - DropOldest: push() never waits. The consumer takes the newest waiting item and counts the
//    older ones it skips as dropped, so a slow stage always works on the newest frame. An SPSC
//    producer cannot remove from the consumer's end, so when the ring is full (the consumer stalled
//    for `capacity` items) the producer parks the incoming item in one overflow slot of its own,
//    replacing (and counting as dropped) the one parked before; the next push or close() moves it
//    into the ring. The newest item is therefore never the one lost.
// End of stream: the producer calls close() after its last push. The consumer then still receives
// everything that was pushed (in DropOldest mode it stops skipping, so a shutdown drains all),
// and pop() reports Closed once the queue is empty.

#include <atomic>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <readerwritercircularbuffer.h>

#include "pipeline/clock.hpp"
#include "pipeline/pop_result.hpp"
#include "pipeline/queue_stats.hpp"
#include "pipeline/stop_flag.hpp"

namespace dynavins::pipeline {

template <typename T>
class SpscQueue final : public QueueBase {
 public:
  using value_type = T;

  /// `stop` is the run's stop flag: waits end when it aborts. It must outlive the queue.
  SpscQueue(std::string name, std::size_t capacity, Backpressure policy, const StopFlag& stop)
      : name_(std::move(name)), policy_(policy), stop_(stop), ring_(capacity) {
    if (capacity == 0) throw std::invalid_argument("queue '" + name_ + "': capacity must be > 0");
    if (policy == Backpressure::DropNewest)
      throw std::invalid_argument("queue '" + name_ + "': SPSC queues support block and drop-oldest");
  }

  /// Producer: enqueue one item. Returns false only if the run was aborted while waiting (Block).
  bool push(T item) {
    Stamped<T> stamped{std::move(item), steady_now_ns()};
    if (policy_ == Backpressure::Block) {
      while (!ring_.wait_enqueue_timed(std::move(stamped), kPollMicros)) {
        if (stop_.aborted()) return false;
      }
    } else {
      // try_enqueue moves only on success, so a failed attempt leaves the item intact.
      if (overflow_ && ring_.try_enqueue(std::move(*overflow_))) overflow_.reset();
      if (overflow_ || !ring_.try_enqueue(std::move(stamped))) {
        if (overflow_) counters_.dropped.fetch_add(1, std::memory_order_relaxed);
        overflow_ = std::move(stamped);
      }
    }
    counters_.pushed.fetch_add(1, std::memory_order_relaxed);
    counters_.note_depth(ring_.size_approx());
    return true;
  }

  /// Producer: enqueue only if there is room right now, whatever the policy; never drops or
  /// counts a drop (for links where a full queue is an error the producer reports, e.g. IMU live).
  bool try_push(T item) {
    if (!ring_.try_enqueue(Stamped<T>{std::move(item), steady_now_ns()})) return false;
    counters_.pushed.fetch_add(1, std::memory_order_relaxed);
    counters_.note_depth(ring_.size_approx());
    return true;
  }

  /// Producer: no more items will come. Everything already pushed is still delivered (a parked
  /// overflow item is moved into the ring first, waiting for room unless the run aborts).
  void close() {
    if (overflow_) {
      while (!ring_.wait_enqueue_timed(std::move(*overflow_), kPollMicros)) {
        if (stop_.aborted()) break;
      }
      overflow_.reset();
    }
    closed_.store(true, std::memory_order_release);
  }

  /// Consumer: wait up to `timeout` for the next item (see the header note for DropOldest).
  PopResult pop(T& out, std::chrono::microseconds timeout, int64_t* enqueued_ns = nullptr) {
    Stamped<T> stamped;
    PopResult r = take(stamped, timeout);
    if (r != PopResult::Item) return r;
    if (policy_ == Backpressure::DropOldest && !closed_.load(std::memory_order_acquire)) {
      Stamped<T> newer;
      while (ring_.try_dequeue(newer)) {  // keep the newest, count what it replaces
        stamped = std::move(newer);
        counters_.dropped.fetch_add(1, std::memory_order_relaxed);
      }
    }
    counters_.delivered.fetch_add(1, std::memory_order_relaxed);
    out = std::move(stamped.value);
    if (enqueued_ns) *enqueued_ns = stamped.enqueued_ns;
    return PopResult::Item;
  }

  bool closed() const { return closed_.load(std::memory_order_acquire); }
  Backpressure policy() const { return policy_; }
  std::size_t capacity() const { return ring_.max_capacity(); }
  const std::string& name() const override { return name_; }

  QueueStats stats() const override {
    QueueStats s;
    s.name = name_;
    s.capacity = ring_.max_capacity();
    s.depth = ring_.size_approx();
    s.max_depth = counters_.max_depth.load(std::memory_order_relaxed);
    s.pushed = counters_.pushed.load(std::memory_order_relaxed);
    s.delivered = counters_.delivered.load(std::memory_order_relaxed);
    s.dropped = counters_.dropped.load(std::memory_order_relaxed);
    return s;
  }

 private:
  static constexpr std::int64_t kPollMicros = 20000;  // how often a blocked wait re-checks abort

  PopResult take(Stamped<T>& out, std::chrono::microseconds timeout) {
    if (stop_.aborted()) return PopResult::Aborted;
    if (ring_.try_dequeue(out)) return PopResult::Item;
    // Everything pushed happens-before close(): if closed is seen, an empty ring means the end.
    if (closed_.load(std::memory_order_acquire)) {
      return ring_.try_dequeue(out) ? PopResult::Item : PopResult::Closed;
    }
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
          deadline - std::chrono::steady_clock::now());
      const std::int64_t wait = std::max<std::int64_t>(0, std::min<std::int64_t>(left.count(), kPollMicros));
      if (ring_.wait_dequeue_timed(out, wait)) return PopResult::Item;
      if (stop_.aborted()) return PopResult::Aborted;
      if (closed_.load(std::memory_order_acquire))
        return ring_.try_dequeue(out) ? PopResult::Item : PopResult::Closed;
      if (left.count() <= kPollMicros) return PopResult::Timeout;
    }
  }

  std::string name_;
  Backpressure policy_;
  const StopFlag& stop_;
  moodycamel::BlockingReaderWriterCircularBuffer<Stamped<T>> ring_;
  std::optional<Stamped<T>> overflow_;  // producer-owned (DropOldest only)
  std::atomic<bool> closed_{false};
  QueueCounters counters_;
};

}  // namespace dynavins::pipeline
