#include <chrono>
#include <thread>
#include <vector>

#include <catch2/catch.hpp>

#include "pipeline/rejected_tracks_feedback.hpp"

using dynavins::pipeline::RejectedTracksFeedback;
using namespace std::chrono_literals;

TEST_CASE("RejectedTracksFeedback: the tracker gets the verdict on exactly the frames before its own", "[feedback]") {
  RejectedTracksFeedback f;
  std::vector<int64_t> ids;
  // Nothing finished yet: frame 0 needs no verdict.
  CHECK(f.wait(0, 0ms, &ids));
  CHECK(ids.empty());
  constexpr int kFrames = 2000;
  // The estimator finishes frame k with verdict {k}; the tracker, before its frame k + 1, must see {k}.
  std::thread estimator([&] {
    for (int64_t k = 0; k < kFrames; ++k) f.publish(k + 1, {k});
    f.close();
  });
  for (int64_t k = 0; k < kFrames; ++k) {
    REQUIRE(f.wait(k + 1, 10s, &ids));
    REQUIRE(ids.size() == 1);
    REQUIRE(ids[0] >= k);  // never an older verdict than asked for
  }
  estimator.join();
  CHECK(f.latest() == std::vector<int64_t>{kFrames - 1});
}

TEST_CASE("RejectedTracksFeedback: a wait ends at the timeout, and at once after close", "[feedback]") {
  RejectedTracksFeedback f;
  f.publish(3, {7, 9});
  std::vector<int64_t> ids;
  CHECK_FALSE(f.wait(4, 20ms, &ids));  // frame 3 not finished: the newest verdict there is
  CHECK(ids == std::vector<int64_t>{7, 9});
  f.finished(4);  // a frame finished without a new verdict (skipped): the waiter goes on with the last one
  ids.clear();
  CHECK(f.wait(4, 0ms, &ids));
  CHECK(ids == std::vector<int64_t>{7, 9});
  std::thread closer([&] {
    std::this_thread::sleep_for(20ms);
    f.close();
  });
  const auto t0 = std::chrono::steady_clock::now();
  CHECK(f.wait(100, 30s, &ids));  // released by close, long before the timeout
  CHECK(std::chrono::steady_clock::now() - t0 < 10s);
  closer.join();
}
