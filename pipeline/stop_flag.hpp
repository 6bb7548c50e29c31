#pragma once
// Shared stop state of one pipeline run. Two ways to end a run (DESIGN.md §2):
//  - graceful stop (end of input, SIGINT): sources stop producing, every stage drains its input;
//  - abort (a stage failed): every blocking wait returns and nothing more is processed.

#include <atomic>

namespace dynavins::pipeline {

class StopFlag {
 public:
  /// Ask sources to stop producing; queued data is still drained.
  void request_stop() { stop_.store(true, std::memory_order_release); }
  /// Abort the run: waits give up, queued data is discarded.
  void abort() {
    abort_.store(true, std::memory_order_release);
    request_stop();
  }
  bool stop_requested() const { return stop_.load(std::memory_order_acquire); }
  bool aborted() const { return abort_.load(std::memory_order_acquire); }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<bool> abort_{false};
};

}  // namespace dynavins::pipeline
