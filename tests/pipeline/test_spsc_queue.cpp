#include <atomic>
#include <thread>

#include <catch2/catch.hpp>

#include "pipeline/spsc_queue.hpp"

using namespace dynavins::pipeline;
using namespace std::chrono_literals;

TEST_CASE("SpscQueue holds at most its capacity", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("q", 4, Backpressure::Block, stop);
  for (int i = 0; i < 4; ++i) REQUIRE(q.try_push(i));
  REQUIRE_FALSE(q.try_push(99));
  CHECK(q.stats().depth == 4);
  CHECK(q.stats().max_depth == 4);
}

TEST_CASE("SpscQueue block mode: a full queue makes the producer wait, abort releases it", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("q", 2, Backpressure::Block, stop);
  REQUIRE(q.push(1));
  REQUIRE(q.push(2));
  std::atomic<bool> returned{false};
  bool result = true;
  std::thread producer([&] {
    result = q.push(3);  // must wait: the queue is full and nobody pops
    returned = true;
  });
  std::this_thread::sleep_for(100ms);
  CHECK_FALSE(returned.load());
  stop.abort();
  producer.join();
  CHECK_FALSE(result);
  CHECK(q.stats().dropped == 0);
}

TEST_CASE("SpscQueue block mode loses and reorders nothing under a fast producer", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("q", 8, Backpressure::Block, stop);
  constexpr int kN = 20000;
  std::atomic<int> refused{0};  // Catch2 assertions are main-thread only: workers count, main checks
  std::thread producer([&] {
    for (int i = 0; i < kN; ++i)
      if (!q.push(i)) refused.fetch_add(1);
    q.close();
  });
  int expected = 0, value = -1;
  PopResult r;
  while ((r = q.pop(value, 100ms)) != PopResult::Closed) {
    if (r != PopResult::Item) continue;
    REQUIRE(value == expected);
    ++expected;
    if (expected % 1000 == 0) std::this_thread::sleep_for(1ms);  // consumer slower than producer
  }
  producer.join();
  CHECK(refused == 0);
  CHECK(expected == kN);
  const auto s = q.stats();
  CHECK(s.pushed == kN);
  CHECK(s.delivered == kN);
  CHECK(s.dropped == 0);
  CHECK(s.max_depth <= 8);
}

TEST_CASE("SpscQueue drop-oldest: the consumer gets the newest, older items are counted as dropped", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("frames", 4, Backpressure::DropOldest, stop);
  for (int i = 0; i < 3; ++i) REQUIRE(q.push(i));
  int v = -1;
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 2);
  CHECK(q.stats().dropped == 2);
  // A full ring never blocks the producer: 10..13 fill it, 14..19 take turns in the overflow slot.
  for (int i = 10; i < 20; ++i) REQUIRE(q.push(i));
  CHECK(q.stats().dropped == 2 + 5);
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 13);  // the newest in the ring; 19 is parked and goes in with the next push
  REQUIRE(q.push(20));
  q.close();
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 19);
  REQUIRE(q.pop(v, 10ms) == PopResult::Item);
  CHECK(v == 20);
  CHECK(q.pop(v, 10ms) == PopResult::Closed);
  const auto s = q.stats();
  CHECK(s.pushed == s.delivered + s.dropped);
}

TEST_CASE("SpscQueue drop-oldest under a slow consumer: increasing order, accounting adds up", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("frames", 4, Backpressure::DropOldest, stop);
  constexpr int kN = 2000;
  std::thread producer([&] {
    for (int i = 0; i < kN; ++i) {
      q.push(i);
      if (i % 50 == 0) std::this_thread::sleep_for(1ms);
    }
    q.close();
  });
  int last = -1, received = 0, v = 0;
  PopResult r;
  while ((r = q.pop(v, 100ms)) != PopResult::Closed) {
    if (r != PopResult::Item) continue;
    REQUIRE(v > last);
    last = v;
    ++received;
    std::this_thread::sleep_for(200us);
  }
  producer.join();
  const auto s = q.stats();
  CHECK(s.pushed == kN);
  CHECK(s.delivered == static_cast<uint64_t>(received));
  CHECK(s.pushed == s.delivered + s.dropped);
  CHECK(s.dropped > 0);
  CHECK(last == kN - 1);  // after close the consumer drains: the newest item is never lost
}

TEST_CASE("SpscQueue close: everything pushed is still delivered, then Closed", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("q", 8, Backpressure::DropOldest, stop);
  for (int i = 0; i < 5; ++i) q.push(i);
  q.close();
  int v = -1;
  for (int i = 0; i < 5; ++i) {
    REQUIRE(q.pop(v, 10ms) == PopResult::Item);
    CHECK(v == i);  // closed: no skipping, a shutdown drains everything
  }
  CHECK(q.pop(v, 10ms) == PopResult::Closed);
}

TEST_CASE("SpscQueue pop times out on an open empty queue and stops on abort", "[spsc]") {
  StopFlag stop;
  SpscQueue<int> q("q", 2, Backpressure::Block, stop);
  int v;
  CHECK(q.pop(v, 5ms) == PopResult::Timeout);
  stop.abort();
  CHECK(q.pop(v, 5ms) == PopResult::Aborted);
}

TEST_CASE("SpscQueue rejects a capacity of zero and the drop-newest policy", "[spsc]") {
  StopFlag stop;
  CHECK_THROWS_AS(SpscQueue<int>("q", 0, Backpressure::Block, stop), std::invalid_argument);
  CHECK_THROWS_AS(SpscQueue<int>("q", 2, Backpressure::DropNewest, stop), std::invalid_argument);
}
