// KeyframeGrouper (paper IV-A, eq. 12) on constructed feature-id sets: where groups close (alpha, the
// size cap), that short groups are dropped, and that F_i^k means "tracked from C_i all the way to C_k".
#include <catch2/catch.hpp>

#include <numeric>

#include "stages/loop/graph/keyframe_grouper.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {
std::vector<int64_t> id_range(int64_t first, int64_t count) {
  std::vector<int64_t> ids(static_cast<size_t>(count));
  std::iota(ids.begin(), ids.end(), first);
  return ids;
}
}  // namespace

TEST_CASE("KeyframeGrouper: a group grows while |F_i^k| >= alpha, then the next one starts", "[loop][grouper]") {
  KeyframeGrouperOptions opt;
  opt.min_shared_features = 25;
  opt.max_group_size = 20;
  opt.min_group_size = 3;
  KeyframeGrouper g(opt);
  // Keyframe k sees ids [10k, 10k + 50): C_0's ids survive in C_k for 50 - 10k of them (>= 25 up to k = 2).
  std::vector<std::optional<KeyframeGroup>> closed;
  for (int k = 0; k < 6; ++k) closed.push_back(g.add_keyframe(100 * k, id_range(10 * k, 50)));
  REQUIRE_FALSE(closed[0]);
  REQUIRE_FALSE(closed[1]);
  REQUIRE_FALSE(closed[2]);
  REQUIRE(closed[3]);  // C_3 shares only 20 ids with C_0: group {C_0, C_1, C_2} closes
  CHECK(closed[3]->t_ns == std::vector<int64_t>{0, 100, 200});
  CHECK(closed[3]->first_t_ns() == 0);
  CHECK_FALSE(closed[4]);
  CHECK_FALSE(closed[5]);
  CHECK(g.open_group().t_ns == std::vector<int64_t>{300, 400, 500});
  CHECK(g.open_shared_features() == 30);  // ids [50, 80) of C_3 are still seen in C_5
  const auto last = g.finish();
  REQUIRE(last);
  CHECK(last->t_ns == std::vector<int64_t>{300, 400, 500});
  CHECK(g.groups().size() == 2);
  CHECK(g.num_dropped() == 0);
}

TEST_CASE("KeyframeGrouper: a feature must be tracked through every keyframe, not only seen again", "[loop][grouper]") {
  KeyframeGrouperOptions opt;
  opt.min_shared_features = 25;
  opt.min_group_size = 1;
  KeyframeGrouper g(opt);
  g.add_keyframe(0, id_range(0, 40));
  g.add_keyframe(1, id_range(0, 30));  // |F| = 30
  // C_2 sees all 40 ids of C_0 again, but ids 30..39 were lost in C_1 (a re-detection gets a new id in
  // the tracker; here we check the intersection semantics): |F_0^2| = 30, still >= 25.
  g.add_keyframe(2, id_range(0, 40));
  CHECK(g.open_shared_features() == 30);
  // C_3 keeps 24 of the 30: the group closes at C_2.
  const auto closed = g.add_keyframe(3, id_range(6, 40));
  REQUIRE(closed);
  CHECK(closed->t_ns == std::vector<int64_t>{0, 1, 2});
}

TEST_CASE("KeyframeGrouper: the size cap closes a group, groups under min_group_size are dropped, the last one kept",
          "[loop][grouper]") {
  KeyframeGrouper g;  // defaults: alpha 25, at most 20 keyframes, groups under 8 dropped
  const std::vector<int64_t> same = id_range(0, 100);
  int num_closed = 0;
  for (int k = 0; k < 45; ++k)
    if (g.add_keyframe(k, same)) ++num_closed;
  CHECK(num_closed == 2);  // closed at k = 20 and k = 40
  REQUIRE(g.groups().size() == 2);
  CHECK(g.groups()[0].t_ns.size() == 20);
  CHECK(g.groups()[0].first_t_ns() == 0);
  CHECK(g.groups()[1].first_t_ns() == 20);
  // finish(): the last 5 keyframes, under 8, are kept (keep_last_group) ...
  KeyframeGrouper kept = g;
  const auto last = kept.finish();
  REQUIRE(last);
  CHECK(last->first_t_ns() == 40);
  CHECK(last->t_ns.size() == 5);
  CHECK(kept.groups().size() == 3);
  CHECK(kept.num_dropped() == 0);
  // ... or dropped like any other short group (the paper).
  KeyframeGrouperOptions paper;
  paper.keep_last_group = false;
  KeyframeGrouper strict(paper);
  for (int k = 0; k < 45; ++k) strict.add_keyframe(k, same);
  CHECK_FALSE(strict.finish());
  CHECK(strict.groups().size() == 2);
  CHECK(strict.num_dropped() == 1);

  // A keyframe with no shared features between two long runs: a group of one, dropped.
  KeyframeGrouper h;
  for (int k = 0; k < 10; ++k) h.add_keyframe(k, id_range(0, 50));
  h.add_keyframe(10, id_range(1000, 50));
  for (int k = 11; k < 21; ++k) h.add_keyframe(k, id_range(2000, 50));
  h.finish();
  REQUIRE(h.groups().size() == 2);
  CHECK(h.groups()[0].t_ns.size() == 10);
  CHECK(h.groups()[1].first_t_ns() == 11);
  CHECK(h.num_dropped() == 1);
}

TEST_CASE("tracked_feature_ids: keeps tracked ids only, sorted and unique", "[loop][grouper]") {
  Keyframe kf;
  for (int64_t id : {5, -1, 3, 5, -1, 9}) {
    KeyframePoint p;
    p.id = id;
    kf.points.push_back(p);
  }
  CHECK(tracked_feature_ids(kf) == std::vector<int64_t>{3, 5, 9});
}
