// VocabularyTree on ORB descriptors of real EuRoC images (a small tree, so the suite stays fast under
// ThreadSanitizer): reproducible from the seed, lossless save/load, clear errors on bad files, and the L1
// score of DBoW2.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include <catch2/catch.hpp>

#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"
#include "tests/loop/place/euroc_images.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {

cv::Mat orb_of_frame(int index, int max_points = 300) {
  Keyframe kf;
  kf.image = test::euroc_cam0_image(index);
  DescriptorOptions opts;
  opts.max_points = max_points;
  return compute_keyframe_descriptors(kf, opts).descriptors;
}

const std::vector<cv::Mat>& training_set() {
  static const std::vector<cv::Mat> kSet = [] {
    std::vector<cv::Mat> s;
    for (int i : {0, 15, 30, 45, 60, 75, 90}) s.push_back(orb_of_frame(i, 250));
    return s;
  }();
  return kSet;
}

VocabularyOptions small_options(uint64_t seed = 7) {
  VocabularyOptions o;
  o.branching = 8;
  o.depth = 3;
  o.seed = seed;
  return o;
}

const VocabularyTree& small_tree() {
  static const VocabularyTree kTree = VocabularyTree::build(training_set(), small_options());
  return kTree;
}

/// A file in the system's temporary directory, unique per process (the Release and TSan passes may overlap).
std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name)).string();
}

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void write_all(const std::string& path, const std::string& data) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(data.data(), static_cast<std::streamsize>(data.size()));
}

}  // namespace

TEST_CASE("vocabulary tree: words, leaves and IDF weights") {
  const VocabularyTree& t = small_tree();
  INFO("words " << t.num_words() << ", nodes " << t.nodes().size());
  CHECK(t.num_words() > 200);
  CHECK(t.num_words() <= 512);
  std::size_t leaves = 0;
  for (const auto& n : t.nodes()) {
    if (n.num_children == 0) {
      ++leaves;
      CHECK(n.weight >= 0.f);
      CHECK(n.weight <= std::log(7.0) + 1e-6);
    }
    CHECK(n.num_children <= 8);
  }
  CHECK(leaves == t.num_words());
  // A training descriptor's word is a valid id; a BoW vector is sorted and L1-normalised.
  const cv::Mat& d = training_set()[2];
  CHECK(t.word_of(d.ptr<uint8_t>(0)) < t.num_words());
  const BowVector v = t.transform(d);
  REQUIRE(!v.empty());
  double sum = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    sum += v[i].weight;
    if (i > 0) CHECK(v[i - 1].word < v[i].word);
  }
  CHECK(sum == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("vocabulary tree: the same seed builds the identical tree") {
  const VocabularyTree again = VocabularyTree::build(training_set(), small_options());
  CHECK(again == small_tree());
  const VocabularyTree other = VocabularyTree::build(training_set(), small_options(8));
  CHECK_FALSE(other == small_tree());
}

TEST_CASE("vocabulary tree: save and load round trip") {
  const std::string path = temp_path("test_loop_place_vocab.bin");
  small_tree().save(path);
  const VocabularyTree loaded = VocabularyTree::load(path);
  CHECK(loaded == small_tree());
  const cv::Mat query = orb_of_frame(50);
  CHECK(loaded.transform(query) == small_tree().transform(query));
  // 48 bytes a node plus a 36-byte header.
  CHECK(read_all(path).size() == 36 + 48 * small_tree().nodes().size());
  std::remove(path.c_str());
}

TEST_CASE("vocabulary tree: a truncated or foreign file is an error naming the file and offset") {
  const std::string path = temp_path("test_loop_place_vocab_bad.bin");
  small_tree().save(path);
  const std::string good = read_all(path);

  write_all(path, good.substr(0, good.size() - 20));
  CHECK_THROWS_WITH(VocabularyTree::load(path),
                    Catch::Contains(path) && Catch::Contains("truncated") && Catch::Contains("offset"));
  write_all(path, good.substr(0, 20));
  CHECK_THROWS_WITH(VocabularyTree::load(path),
                    Catch::Contains(path) && Catch::Contains("truncated while reading the node count at offset 20"));
  std::string bad = good;
  bad[0] = 'X';
  write_all(path, bad);
  CHECK_THROWS_WITH(VocabularyTree::load(path), Catch::Contains(path) && Catch::Contains("bad magic"));
  bad = good;
  bad[8] = 9;  // version
  write_all(path, bad);
  CHECK_THROWS_WITH(VocabularyTree::load(path), Catch::Contains("version 9"));
  write_all(path, good + "xx");
  CHECK_THROWS_WITH(VocabularyTree::load(path), Catch::Contains("trailing bytes"));
  std::remove(path.c_str());
  CHECK_THROWS_WITH(VocabularyTree::load(path), Catch::Contains(path) && Catch::Contains("cannot open"));
}

TEST_CASE("bow vector: the L1 score of DBoW2") {
  const BowVector a{{1, 0.5}, {3, 0.25}, {7, 0.25}};
  const BowVector b{{1, 0.25}, {4, 0.5}, {7, 0.25}};
  const BowVector c{{2, 1.0}};
  CHECK(l1_score(a, a) == Approx(1.0));
  CHECK(l1_score(a, c) == 0.0);
  // 1 - |a - b|_1 / 2 = 1 - (0.25 + 0.25 + 0.5 + 0) / 2
  CHECK(l1_score(a, b) == Approx(0.5));
  CHECK(l1_score(b, a) == l1_score(a, b));
}

TEST_CASE("vocabulary tree: build rejects bad input") {
  CHECK_THROWS(VocabularyTree::build({}, small_options()));
  CHECK_THROWS(VocabularyTree::build({cv::Mat(3, 16, CV_8UC1)}, small_options()));
}

TEST_CASE("vocabulary tree: build_vocabulary, the entry point of `dynavins vocab`, is VocabularyTree::build") {
  CHECK(build_vocabulary(training_set(), small_options()) == small_tree());
}
