#include <atomic>
#include <csignal>
#include <stdexcept>
#include <thread>
#include <vector>

#include <pthread.h>
#include <sched.h>

#include <catch2/catch.hpp>

#include "pipeline/interrupt.hpp"
#include "pipeline/pipeline.hpp"

using namespace dynavins::pipeline;
using namespace std::chrono_literals;

namespace {

struct Doubler {
  int process(int x) { return 2 * x; }
};

/// Emits its inputs in batches of three, and the partial batch in finish().
struct Batcher {
  std::vector<int> batch;
  std::optional<std::vector<int>> process(int x) {
    batch.push_back(x);
    if (batch.size() < 3) return std::nullopt;
    return std::exchange(batch, {});
  }
  std::optional<std::vector<int>> finish() {
    if (batch.empty()) return std::nullopt;
    return std::exchange(batch, {});
  }
};

struct Collector {
  std::vector<int> seen;
  std::vector<std::size_t> batch_sizes;
  void process(std::vector<int> b) {
    batch_sizes.push_back(b.size());
    seen.insert(seen.end(), b.begin(), b.end());
  }
};

struct Slow {
  std::chrono::microseconds cost;
  int process(int x) {
    std::this_thread::sleep_for(cost);
    return x;
  }
};

struct Sink {
  std::vector<int> seen;
  void process(int x) { seen.push_back(x); }
};

struct Thrower {
  int processed = 0;
  int process(int x) {
    if (++processed == 10) throw std::runtime_error("bad input at item 10");
    return x;
  }
};

/// Records the scheduling policy of the thread that runs it.
struct PolicyProbe {
  int policy = -1;
  int priority = -1;
  void process(int) {
    sched_param param{};
    pthread_getschedparam(pthread_self(), &policy, &param);
    priority = param.sched_priority;
  }
};

}  // namespace

TEST_CASE("Pipeline: set_thread_realtime runs that thread under SCHED_FIFO when allowed, and says so", "[pipeline]") {
  Pipeline p;
  auto& a = p.add_queue<int>("a", 4, Backpressure::Block);
  auto& b = p.add_queue<int>("b", 4, Backpressure::Block);
  p.add_source(
      "source", [&](const StopFlag&) { a.push(1), b.push(1); },
      [&] {
        a.close();
        b.close();
      });
  PolicyProbe fast, normal;
  p.add_stage("fast", fast, a, NoOutput{}, {});
  p.add_stage("normal", normal, b, NoOutput{}, {});
  CHECK_THROWS_WITH(p.set_thread_realtime("nonexistent", 10), Catch::Contains("no thread named 'nonexistent'"));
  CHECK_THROWS_WITH(p.set_thread_realtime("fast", 0), Catch::Contains("[1, 99]"));
  p.set_thread_realtime("fast", 7);
  REQUIRE(p.run().ok);

  // Granted (root, CAP_SYS_NICE or an rtprio limit) or refused, it is counted, and the run went on.
  REQUIRE(p.realtime_threads() + p.realtime_refused() == 1);
  if (p.realtime_threads() == 1) {
    CHECK(fast.policy == SCHED_FIFO);
    CHECK(fast.priority == 7);
  } else {
    CHECK(fast.policy == SCHED_OTHER);
  }
  CHECK(normal.policy == SCHED_OTHER);
}

TEST_CASE("Pipeline: a chain loses and reorders nothing, finish() flushes, queues drain", "[pipeline]") {
  Pipeline p;
  auto& a = p.add_queue<int>("a", 4, Backpressure::Block);
  auto& b = p.add_queue<int>("b", 4, Backpressure::Block);
  auto& c = p.add_queue<std::vector<int>>("c", 2, Backpressure::Block);
  constexpr int kN = 5000;
  p.add_source(
      "source", [&](const StopFlag&) {
        for (int i = 0; i < kN; ++i) a.push(i);  // far faster than the consumers
      },
      [&] { a.close(); });
  Doubler d;
  Batcher batcher;
  Collector collect;
  p.add_stage("double", d, a, into(b), [&] { b.close(); });
  p.add_stage("batch", batcher, b, into(c), [&] { c.close(); });
  p.add_stage("collect", collect, c, NoOutput{}, {});
  const RunReport r = p.run();

  REQUIRE(r.ok);
  CHECK_FALSE(r.interrupted);
  REQUIRE(collect.seen.size() == kN);
  for (int i = 0; i < kN; ++i) REQUIRE(collect.seen[i] == 2 * i);
  CHECK(collect.batch_sizes.back() == kN % 3);  // the partial batch came from finish()
  for (const auto& q : r.queues) {
    CHECK(q.depth == 0);
    CHECK(q.dropped == 0);
    CHECK(q.max_depth <= q.capacity);
  }
  REQUIRE(r.stages.size() == 4);
  CHECK(r.stages[1].name == "double");
  CHECK(r.stages[1].processed == kN);
  CHECK(r.stages[1].process.count == kN);
  for (const auto& s : r.stages) CHECK(s.finished);
}

TEST_CASE("Pipeline: a stage that throws stops the run with its error, no hang", "[pipeline]") {
  Pipeline p;
  auto& a = p.add_queue<int>("a", 2, Backpressure::Block);
  auto& b = p.add_queue<int>("b", 2, Backpressure::Block);
  // An endless source: only the abort can end this run.
  p.add_source(
      "source", [&](const StopFlag& stop) {
        for (int i = 0; !stop.stop_requested(); ++i) a.push(i);
      },
      [&] { a.close(); });
  Thrower thrower;
  Sink sink;
  p.add_stage("thrower", thrower, a, into(b), [&] { b.close(); });
  p.add_stage("sink", sink, b, NoOutput{}, {});
  const RunReport r = p.run();
  CHECK_FALSE(r.ok);
  CHECK(r.failed_thread == "thrower");
  CHECK(r.error == "bad input at item 10");
  CHECK(sink.seen.size() <= 9);
}

TEST_CASE("Pipeline: a source that throws is reported too", "[pipeline]") {
  Pipeline p;
  auto& a = p.add_queue<int>("a", 2, Backpressure::Block);
  p.add_source(
      "replay", [&](const StopFlag&) {
        a.push(1);
        throw std::runtime_error("log.lcmlog: event 3 at byte 120: truncated");
      },
      [&] { a.close(); });
  Sink sink;
  p.add_stage("sink", sink, a, NoOutput{}, {});
  const RunReport r = p.run();
  CHECK_FALSE(r.ok);
  CHECK(r.failed_thread == "replay");
  CHECK(r.error.find("truncated") != std::string::npos);
}

TEST_CASE("Pipeline: request_stop ends an endless source and drains every queue", "[pipeline]") {
  Pipeline p;
  auto& a = p.add_queue<int>("a", 8, Backpressure::Block);
  auto& b = p.add_queue<int>("b", 8, Backpressure::Block);
  std::atomic<int> produced{0};
  p.add_source(
      "source", [&](const StopFlag& stop) {
        for (int i = 0; !stop.stop_requested(); ++i) {
          if (a.push(i)) produced.fetch_add(1);
        }
      },
      [&] { a.close(); });
  Slow slow{200us};
  Sink sink;
  p.add_stage("slow", slow, a, into(b), [&] { b.close(); });
  p.add_stage("sink", sink, b, NoOutput{}, {});
  std::thread stopper([&] {
    while (produced.load() < 200) std::this_thread::sleep_for(1ms);
    p.request_stop();
  });
  const RunReport r = p.run();
  stopper.join();
  REQUIRE(r.ok);
  CHECK(r.interrupted);
  // Every item the source managed to push made it through: nothing left in a queue.
  REQUIRE(static_cast<int>(sink.seen.size()) == produced.load());
  for (std::size_t i = 0; i < sink.seen.size(); ++i) REQUIRE(sink.seen[i] == static_cast<int>(i));
}

TEST_CASE("Pipeline: SIGINT stops the sources gracefully and the queues drain", "[pipeline]") {
  install_interrupt_handler();
  clear_interrupt();
  Pipeline p;
  auto& a = p.add_queue<int>("a", 8, Backpressure::Block);
  std::atomic<int> produced{0};
  p.add_source(
      "source", [&](const StopFlag& stop) {
        for (int i = 0; !stop.stop_requested(); ++i) {
          if (a.push(i)) produced.fetch_add(1);
          if (i == 100) std::raise(SIGINT);
        }
      },
      [&] { a.close(); });
  Slow slow{50us};
  p.add_stage("slow", slow, a, NoOutput{}, {});
  const RunReport r = p.run();
  clear_interrupt();
  REQUIRE(r.ok);
  CHECK(r.interrupted);
  CHECK(r.stages[1].processed == static_cast<uint64_t>(produced.load()));
}

TEST_CASE("Pipeline: real-time pacing with drop-oldest keeps order and counts every drop", "[pipeline]") {
  Pipeline p;
  auto& frames = p.add_queue<int>("frames", 2, Backpressure::DropOldest);
  constexpr int kN = 300;
  p.add_source(
      "camera", [&](const StopFlag&) {
        for (int i = 0; i < kN; ++i) {
          frames.push(i);
          std::this_thread::sleep_for(200us);  // the camera outpaces the stage
        }
      },
      [&] { frames.close(); });
  Slow slow{1ms};
  Sink sink;
  auto& out = p.add_queue<int>("out", 4, Backpressure::Block);
  p.add_stage("tracker", slow, frames, into(out), [&] { out.close(); });
  p.add_stage("sink", sink, out, NoOutput{}, {});
  const RunReport r = p.run();
  REQUIRE(r.ok);
  const auto& q = r.queues[0];
  CHECK(q.dropped > 0);
  CHECK(q.pushed == kN);
  CHECK(q.delivered == sink.seen.size());
  CHECK(q.pushed == q.delivered + q.dropped);
  for (std::size_t i = 1; i < sink.seen.size(); ++i) REQUIRE(sink.seen[i] > sink.seen[i - 1]);
  CHECK(sink.seen.back() == kN - 1);
}
