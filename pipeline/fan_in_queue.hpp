#pragma once
// Bounded multi-producer single-consumer link (fan-in, e.g. every stage to the publisher), over
// moodycamel's BlockingConcurrentQueue. ConcurrentQueue has no hard bound of its own, so a
// LightweightSemaphore counting free slots enforces `capacity`. Lock-free, no mutex.
//
// Each producing thread gets its own Producer handle (moodycamel keeps per-producer FIFO order,
// which is all the consumer relies on). Back-pressure: Block (wait for a free slot) or DropNewest
// (an item that finds the queue full is dropped and counted). The queue is closed when every
// producer has closed; the consumer still receives everything pushed before that.

#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include <concurrentqueue/blockingconcurrentqueue.h>

#include "pipeline/clock.hpp"
#include "pipeline/pop_result.hpp"
#include "pipeline/queue_stats.hpp"
#include "pipeline/stop_flag.hpp"

namespace dynavins::pipeline {

template <typename T>
class FanInQueue final : public QueueBase {
 public:
  using value_type = T;

  class Producer {
   public:
    explicit Producer(FanInQueue& q) : q_(q), token_(q.queue_) {}
    Producer(const Producer&) = delete;
    Producer& operator=(const Producer&) = delete;
    ~Producer() { close(); }

    /// Enqueue one item; false if it was dropped (DropNewest, full) or the run aborted (Block).
    bool push(T item) {
      q_.counters_.pushed.fetch_add(1, std::memory_order_relaxed);
      if (q_.policy_ == Backpressure::Block) {
        while (!q_.free_slots_.wait(kPollMicros)) {
          if (q_.stop_.aborted()) return false;
        }
      } else if (!q_.free_slots_.tryWait()) {
        q_.counters_.dropped.fetch_add(1, std::memory_order_relaxed);
        return false;
      }
      q_.queue_.enqueue(token_, Stamped<T>{std::move(item), steady_now_ns()});
      q_.counters_.note_depth(q_.queue_.size_approx());
      return true;
    }

    /// This producer is done; the queue closes when the last producer closes.
    void close() {
      if (closed_) return;
      closed_ = true;
      q_.open_producers_.fetch_sub(1, std::memory_order_acq_rel);
    }

   private:
    FanInQueue& q_;
    moodycamel::ProducerToken token_;
    bool closed_ = false;
  };

  FanInQueue(std::string name, std::size_t capacity, Backpressure policy, const StopFlag& stop)
      : name_(std::move(name)),
        capacity_(capacity),
        policy_(policy),
        stop_(stop),
        queue_(capacity),
        free_slots_(static_cast<moodycamel::LightweightSemaphore::ssize_t>(capacity)) {
    if (capacity == 0) throw std::invalid_argument("queue '" + name_ + "': capacity must be > 0");
    if (policy == Backpressure::DropOldest)
      throw std::invalid_argument("queue '" + name_ + "': fan-in queues support block and drop-newest");
  }

  /// Registers a producer. Call from the wiring before the threads start.
  std::unique_ptr<Producer> make_producer() {
    open_producers_.fetch_add(1, std::memory_order_acq_rel);
    return std::make_unique<Producer>(*this);
  }

  /// Consumer: wait up to `timeout` for the next item.
  PopResult pop(T& out, std::chrono::microseconds timeout, int64_t* enqueued_ns = nullptr) {
    Stamped<T> stamped;
    PopResult r = take(stamped, timeout);
    if (r != PopResult::Item) return r;
    free_slots_.signal();
    counters_.delivered.fetch_add(1, std::memory_order_relaxed);
    out = std::move(stamped.value);
    if (enqueued_ns) *enqueued_ns = stamped.enqueued_ns;
    return PopResult::Item;
  }

  bool closed() const { return open_producers_.load(std::memory_order_acquire) == 0; }
  const std::string& name() const override { return name_; }

  QueueStats stats() const override {
    QueueStats s;
    s.name = name_;
    s.capacity = capacity_;
    s.depth = queue_.size_approx();
    s.max_depth = counters_.max_depth.load(std::memory_order_relaxed);
    s.pushed = counters_.pushed.load(std::memory_order_relaxed);
    s.delivered = counters_.delivered.load(std::memory_order_relaxed);
    s.dropped = counters_.dropped.load(std::memory_order_relaxed);
    return s;
  }

 private:
  static constexpr std::int64_t kPollMicros = 20000;

  PopResult take(Stamped<T>& out, std::chrono::microseconds timeout) {
    if (stop_.aborted()) return PopResult::Aborted;
    if (queue_.try_dequeue(out)) return PopResult::Item;
    if (closed()) return queue_.try_dequeue(out) ? PopResult::Item : PopResult::Closed;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
          deadline - std::chrono::steady_clock::now());
      const std::int64_t wait = std::max<std::int64_t>(0, std::min<std::int64_t>(left.count(), kPollMicros));
      if (queue_.wait_dequeue_timed(out, wait)) return PopResult::Item;
      if (stop_.aborted()) return PopResult::Aborted;
      if (closed()) return queue_.try_dequeue(out) ? PopResult::Item : PopResult::Closed;
      if (left.count() <= kPollMicros) return PopResult::Timeout;
    }
  }

  std::string name_;
  std::size_t capacity_;
  Backpressure policy_;
  const StopFlag& stop_;
  moodycamel::BlockingConcurrentQueue<Stamped<T>> queue_;
  moodycamel::LightweightSemaphore free_slots_;
  std::atomic<int> open_producers_{0};
  QueueCounters counters_;
};

}  // namespace dynavins::pipeline
