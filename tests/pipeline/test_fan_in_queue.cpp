#include <atomic>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "pipeline/fan_in_queue.hpp"

using namespace dynavins::pipeline;
using namespace std::chrono_literals;

namespace {
struct Item {
  int producer = 0;
  int seq = 0;
};
}  // namespace

TEST_CASE("FanInQueue block mode: every producer's items arrive, in order, within capacity", "[fanin]") {
  StopFlag stop;
  FanInQueue<Item> q("publisher", 8, Backpressure::Block, stop);
  constexpr int kProducers = 3, kN = 5000;
  std::vector<std::unique_ptr<FanInQueue<Item>::Producer>> handles;
  for (int p = 0; p < kProducers; ++p) handles.push_back(q.make_producer());
  std::vector<std::thread> threads;
  std::atomic<int> refused{0};  // Catch2 assertions are main-thread only: workers count, main checks
  for (int p = 0; p < kProducers; ++p) {
    threads.emplace_back([&, p] {
      for (int i = 0; i < kN; ++i)
        if (!handles[p]->push({p, i})) refused.fetch_add(1);
      handles[p]->close();
    });
  }
  std::vector<int> next(kProducers, 0);
  Item it;
  PopResult r;
  int total = 0;
  while ((r = q.pop(it, 100ms)) != PopResult::Closed) {
    if (r != PopResult::Item) continue;
    REQUIRE(it.seq == next[it.producer]);
    ++next[it.producer];
    ++total;
  }
  for (auto& t : threads) t.join();
  CHECK(refused == 0);
  CHECK(total == kProducers * kN);
  const auto s = q.stats();
  CHECK(s.dropped == 0);
  CHECK(s.delivered == static_cast<uint64_t>(kProducers * kN));
  CHECK(s.max_depth <= 8 + kProducers);  // depth is sampled after enqueue, racing with other producers
}

TEST_CASE("FanInQueue is bounded: a full queue blocks (block) or drops the newcomer (drop-newest)", "[fanin]") {
  StopFlag stop;
  FanInQueue<int> dropping("q", 4, Backpressure::DropNewest, stop);
  auto p = dropping.make_producer();
  int accepted = 0;
  for (int i = 0; i < 10; ++i) accepted += p->push(i) ? 1 : 0;
  CHECK(accepted == 4);
  CHECK(dropping.stats().dropped == 6);
  int v;
  REQUIRE(dropping.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 0);  // the oldest stays: drop-newest

  FanInQueue<int> blocking("q", 2, Backpressure::Block, stop);
  auto b = blocking.make_producer();
  REQUIRE(b->push(1));
  REQUIRE(b->push(2));
  bool result = true;
  std::thread t([&] { result = b->push(3); });
  std::this_thread::sleep_for(50ms);
  stop.abort();
  t.join();
  CHECK_FALSE(result);
}

TEST_CASE("FanInQueue closes only when every producer has closed", "[fanin]") {
  StopFlag stop;
  FanInQueue<int> q("q", 4, Backpressure::Block, stop);
  auto a = q.make_producer();
  auto b = q.make_producer();
  a->push(1);
  a->close();
  int v;
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(q.pop(v, 10ms) == PopResult::Timeout);
  b->push(2);
  b.reset();  // destroying a handle closes it
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 2);
  CHECK(q.pop(v, 10ms) == PopResult::Closed);
}
