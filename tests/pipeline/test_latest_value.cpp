#include <thread>

#include <catch2/catch.hpp>

#include "pipeline/latest_value.hpp"

using dynavins::pipeline::LatestValue;

namespace {
struct State {
  long a = 0;
  long b = 0;  // always 2a: a torn read would break it
};
}  // namespace

TEST_CASE("LatestValue: nothing before the first write, then whole, fresh values", "[latest]") {
  LatestValue<State> v;
  CHECK_FALSE(v.read().has_value());
  constexpr long kN = 200000;
  std::thread writer([&] {
    for (long i = 1; i <= kN; ++i) v.write({i, 2 * i});
  });
  long last = 0;
  while (last < kN) {
    if (auto s = v.read()) {
      REQUIRE(s->b == 2 * s->a);
      REQUIRE(s->a >= last);  // never goes back in time
      last = s->a;
    }
  }
  writer.join();
  CHECK(v.read()->a == kN);
}
