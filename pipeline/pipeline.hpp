#pragma once
// The stage-thread framework (DESIGN.md §2). A stage is a plain object with
//     Output process(Input)          // Output: a value, std::optional, std::vector, or void
//     Output finish()                // optional: flush at end of stream
// and knows nothing of threads. The Pipeline runs each source and stage on its own thread,
// linked by bounded lock-free queues it owns, measures every stage (processing time and queue
// wait) and every queue (depth, drops), and ends the run in one of two ways:
//  - graceful: the sources finish (end of input) or are stopped (request_stop, SIGINT); each stage
//    drains its input, calls finish(), closes its outputs, and the next stage does the same;
//  - abort: a source or stage throws; the error is recorded, every thread stops, run() reports it.

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "pipeline/clock.hpp"
#include "pipeline/emit.hpp"
#include "pipeline/fan_in_queue.hpp"
#include "pipeline/latency_histogram.hpp"
#include "pipeline/spsc_queue.hpp"
#include "pipeline/stop_flag.hpp"

namespace dynavins::pipeline {

struct StageStats {
  std::string name;
  uint64_t processed = 0;
  LatencySummary process;  ///< time inside process()
  LatencySummary wait;     ///< time items waited in the input queue
  bool finished = false;
};

struct RunReport {
  bool ok = true;
  bool interrupted = false;  ///< stopped by request_stop() or SIGINT (still a clean drain)
  std::string failed_thread;
  std::string error;
  double wall_s = 0.0;
  std::vector<StageStats> stages;
  std::vector<QueueStats> queues;
};

namespace detail {
template <typename S, typename = void>
struct has_finish : std::false_type {};
template <typename S>
struct has_finish<S, std::void_t<decltype(std::declval<S&>().finish())>> : std::true_type {};
}  // namespace detail

class Pipeline {
 public:
  Pipeline() = default;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  ~Pipeline();  ///< aborts and joins threads still running (only after an exception in the caller)

  /// A bounded SPSC link. The pipeline owns it; the reference stays valid for its lifetime.
  template <typename T>
  SpscQueue<T>& add_queue(std::string name, std::size_t capacity, Backpressure policy) {
    auto q = std::make_unique<SpscQueue<T>>(std::move(name), capacity, policy, stop_);
    auto& ref = *q;
    queues_.push_back(std::move(q));
    return ref;
  }

  /// A bounded MPSC link; every producer takes a handle with make_producer() before run().
  template <typename T>
  FanInQueue<T>& add_fan_in(std::string name, std::size_t capacity, Backpressure policy) {
    auto q = std::make_unique<FanInQueue<T>>(std::move(name), capacity, policy, stop_);
    auto& ref = *q;
    queues_.push_back(std::move(q));
    return ref;
  }

  /// A source: `body` produces into its queues until its input ends or stop.stop_requested();
  /// `close_outputs` runs afterwards on the same thread, also when body throws.
  void add_source(std::string name, std::function<void(const StopFlag&)> body,
                  std::function<void()> close_outputs);

  /// A stage on its own thread: pops `input`, hands stage.process(item) to `emit`, and at end of
  /// stream hands stage.finish() (if the stage has one) to `emit`, then runs `close_outputs`.
  template <typename Stage, typename Queue, typename Emit>
  void add_stage(std::string name, Stage& stage, Queue& input, Emit emit, std::function<void()> close_outputs);

  /// Runs the named source or stage under the real-time FIFO scheduler at `priority` (1-99) when the
  /// process may (root, CAP_SYS_NICE or an rtprio limit; otherwise it stays a normal thread and the
  /// summary says so). Real-time runs use it for the light, latency-critical threads (IMU propagation,
  /// publisher), so that a busy machine does not hold up the IMU-rate pose. Call before run().
  void set_thread_realtime(const std::string& name, int priority);

  /// Threads that asked for real-time scheduling and got it / did not (after run()).
  int realtime_threads() const { return realtime_granted_.load(std::memory_order_relaxed); }
  int realtime_refused() const { return realtime_refused_.load(std::memory_order_relaxed); }

  /// Starts every thread and blocks until all have ended. Watches SIGINT (see interrupt.hpp).
  RunReport run();

  /// Graceful stop from any thread: sources stop, queues drain.
  void request_stop() { stop_.request_stop(); }
  const StopFlag& stop_flag() const { return stop_; }

  /// Live statistics; safe to call from any thread while running.
  std::vector<StageStats> stage_stats() const;
  std::vector<QueueStats> queue_stats() const;

 private:
  struct StageRecord {
    std::string name;
    LatencyHistogram process;
    LatencyHistogram wait;
    std::atomic<uint64_t> processed{0};
    std::atomic<bool> finished{false};
    int realtime_priority = 0;  ///< set_thread_realtime(); applied by the thread itself when it starts
  };

  StageRecord& add_record(std::string name);
  void fail(const std::string& thread, const std::string& what);
  void launch(StageRecord& rec, std::function<void()> body, std::function<void()> close_outputs);

  template <typename Stage, typename Emit, typename Item>
  static void process_one(Stage& stage, Emit& emit, Item&& item) {
    if constexpr (std::is_void_v<decltype(stage.process(std::forward<Item>(item)))>) {
      stage.process(std::forward<Item>(item));
    } else {
      emit(stage.process(std::forward<Item>(item)));
    }
  }

  StopFlag stop_;
  std::vector<std::unique_ptr<QueueBase>> queues_;
  std::vector<std::unique_ptr<StageRecord>> records_;
  std::vector<std::function<void()>> bodies_;  // filled by add_*, started by run()
  std::vector<std::thread> threads_;
  std::atomic<int> running_{0};
  std::atomic<int> realtime_granted_{0};
  std::atomic<int> realtime_refused_{0};
  std::mutex error_mutex_;  // error path only, never the data path
  std::string failed_thread_;
  std::string error_;
};

template <typename Stage, typename Queue, typename Emit>
void Pipeline::add_stage(std::string name, Stage& stage, Queue& input, Emit emit,
                         std::function<void()> close_outputs) {
  StageRecord& rec = add_record(std::move(name));
  auto loop = [&stage, &input, &rec, emit = std::move(emit)]() mutable {
    typename Queue::value_type item{};
    for (;;) {
      int64_t enqueued_ns = 0;
      const PopResult r = input.pop(item, std::chrono::milliseconds(50), &enqueued_ns);
      if (r == PopResult::Timeout) continue;
      if (r == PopResult::Aborted) return;
      if (r == PopResult::Closed) {
        if constexpr (detail::has_finish<Stage>::value) {
          if constexpr (std::is_void_v<decltype(stage.finish())>) {
            stage.finish();
          } else {
            emit(stage.finish());
          }
        }
        return;
      }
      const int64_t t0 = steady_now_ns();
      rec.wait.record(t0 - enqueued_ns);
      process_one(stage, emit, std::move(item));
      rec.process.record(steady_now_ns() - t0);
      rec.processed.fetch_add(1, std::memory_order_relaxed);
    }
  };
  launch(rec, std::move(loop), std::move(close_outputs));
}

}  // namespace dynavins::pipeline
