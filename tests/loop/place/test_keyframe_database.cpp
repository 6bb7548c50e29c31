// KeyframeDatabase: its inverted-index scores equal l1_score, the exclusions hold, and on the real EuRoC
// clip a query image finds a frame of the same scene first while other places score lower.
#include <algorithm>
#include <random>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "stages/loop/place/keyframe_database.hpp"
#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"
#include "tests/loop/place/euroc_images.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {

BowVector random_bow(std::mt19937& rng, int words, int vocabulary) {
  std::uniform_int_distribution<int> w(0, vocabulary - 1);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  std::vector<uint32_t> ids;
  while (static_cast<int>(ids.size()) < words) {
    const auto id = static_cast<uint32_t>(w(rng));
    if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  BowVector v;
  double sum = 0;
  for (uint32_t id : ids) v.push_back({id, u(rng)}), sum += v.back().weight;
  for (auto& e : v) e.weight /= sum;
  return v;
}

cv::Mat orb_of(const cv::Mat& image) {
  Keyframe kf;
  kf.image = image;
  DescriptorOptions opts;
  opts.max_points = 300;
  return compute_keyframe_descriptors(kf, opts).descriptors;
}

}  // namespace

TEST_CASE("keyframe database: scores are the L1 scores, best first") {
  std::mt19937 rng(3);
  KeyframeDatabase db;
  std::vector<BowVector> bows;
  for (int i = 0; i < 50; ++i) bows.push_back(random_bow(rng, 40, 300)), db.add(10 * i, 1000 * i, bows.back());
  CHECK(db.size() == 50);
  CHECK_THROWS(db.add(0, 0, bows[0]));
  const BowVector q = random_bow(rng, 40, 300);
  DatabaseQueryOptions opts;
  opts.max_results = 50;
  const auto all = db.query(q, opts);
  REQUIRE(!all.empty());
  for (std::size_t i = 0; i < all.size(); ++i) {
    CHECK(all[i].score == Approx(l1_score(q, bows[all[i].keyframe_id / 10])).margin(1e-12));
    CHECK(all[i].t_ns == all[i].keyframe_id * 100);
    if (i > 0) CHECK(all[i - 1].score >= all[i].score);
  }
  // A stored vector finds itself with score 1.
  const auto self = db.query(bows[17]);
  REQUIRE(!self.empty());
  CHECK(self[0].keyframe_id == 170);
  CHECK(self[0].score == Approx(1.0));
  CHECK(self.size() <= 3);
}

TEST_CASE("keyframe database: a removed keyframe is no longer a candidate, the others score the same") {
  std::mt19937 rng(5);
  KeyframeDatabase db;
  std::vector<BowVector> bows;
  for (int i = 0; i < 30; ++i) bows.push_back(random_bow(rng, 30, 200)), db.add(i, 1000 * i, bows.back());
  const std::size_t postings = db.num_postings(), bytes = db.memory_bytes();
  CHECK(postings == 30 * 30);
  DatabaseQueryOptions opts;
  opts.max_results = 100;
  const auto before = db.query(bows[12], opts);
  db.remove(12, bows[12]);
  CHECK(db.num_postings() == postings - 30);
  CHECK(db.memory_bytes() <= bytes);
  CHECK(db.size() == 30);  // still counted for exclude_recent
  const auto after = db.query(bows[12], opts);
  CHECK(after.size() + 1 == before.size());
  for (const auto& c : after) {
    CHECK(c.keyframe_id != 12);
    CHECK(c.score == Approx(l1_score(bows[12], bows[static_cast<std::size_t>(c.keyframe_id)])).margin(1e-12));
  }
  CHECK_THROWS_AS(db.remove(99, bows[0]), std::invalid_argument);
  CHECK_THROWS(db.add(12, 0, bows[12]));  // the id stays taken
  for (int i = 0; i < 30; ++i)
    if (i != 12) db.remove(i, bows[static_cast<std::size_t>(i)]);
  CHECK(db.num_postings() == 0);
  CHECK(db.query(bows[3], opts).empty());
}

TEST_CASE("keyframe database: exclusions by time and by recency") {
  std::mt19937 rng(4);
  KeyframeDatabase db;
  std::vector<BowVector> bows;
  for (int i = 0; i < 20; ++i) bows.push_back(random_bow(rng, 30, 100)), db.add(i, 1000 * i, bows.back());
  DatabaseQueryOptions opts;
  opts.max_results = 100;
  opts.exclude_recent = 5;
  for (const auto& c : db.query(bows[19], opts)) CHECK(c.keyframe_id < 15);
  opts.exclude_recent = 0;
  opts.max_t_ns = 7000;
  const auto before = db.query(bows[19], opts);
  REQUIRE(!before.empty());
  for (const auto& c : before) CHECK(c.t_ns <= 7000);
  opts.exclude_recent = 100;
  CHECK(db.query(bows[3], opts).empty());
  opts = {};
  opts.min_score = 0.99;
  const auto strict = db.query(bows[3], opts);
  REQUIRE(strict.size() == 1);
  CHECK(strict[0].keyframe_id == 3);
}

TEST_CASE("keyframe database: EuRoC query finds the same scene first, other places lower") {
  // Vocabulary from a few frames of the clip; the database holds frames 0, 10, ..., 90 and, as "other
  // places", the same frames turned upside down (upright ORB describes them differently). The drone stands
  // still in this clip, so every upright frame is the same place.
  std::vector<cv::Mat> train;
  for (int i : {0, 30, 60, 90}) {
    train.push_back(orb_of(test::euroc_cam0_image(i)));
    cv::Mat flipped;
    cv::flip(test::euroc_cam0_image(i), flipped, -1);
    train.push_back(orb_of(flipped));
  }
  VocabularyOptions vo;
  vo.branching = 8;
  vo.depth = 3;
  const VocabularyTree voc = VocabularyTree::build(train, vo);
  KeyframeDatabase db;
  for (int i = 0; i <= 90; i += 10) {
    const cv::Mat img = test::euroc_cam0_image(i);
    cv::Mat flipped;
    cv::flip(img, flipped, -1);
    db.add(i, i, voc.transform(orb_of(img)));
    db.add(1000 + i, 1000 + i, voc.transform(orb_of(flipped)));
  }
  DatabaseQueryOptions opts;
  opts.max_results = 20;
  const auto found = db.query(voc.transform(orb_of(test::euroc_cam0_image(45))), opts);
  REQUIRE(found.size() == 20);
  std::string ranking;
  for (const auto& c : found) ranking += std::to_string(c.keyframe_id) + ":" + std::to_string(c.score) + " ";
  INFO(ranking);
  CHECK((found[0].keyframe_id == 40 || found[0].keyframe_id == 50));
  // All ten upright frames come before every upside-down one, by a wide margin.
  for (int i = 0; i < 10; ++i) CHECK(found[i].keyframe_id < 1000);
  CHECK(found[9].score > 2 * found[10].score);
  // A frame of the database finds itself with score 1.
  const auto self = db.query(voc.transform(orb_of(test::euroc_cam0_image(60))));
  REQUIRE(!self.empty());
  CHECK(self[0].keyframe_id == 60);
  CHECK(self[0].score == Approx(1.0));
}
