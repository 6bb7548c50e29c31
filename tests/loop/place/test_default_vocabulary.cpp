// The default vocabulary shipped in git (data/vocabulary/default_vocabulary.bin, built by
// scripts/build-vocabulary.sh, `make vocab`): it loads, is small, and tells places of the real EuRoC clip apart.
#include <filesystem>
#include <string>

#include <catch2/catch.hpp>
#include <opencv2/core.hpp>

#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"
#include "tests/loop/place/euroc_images.hpp"

using namespace dynavins;
using namespace dynavins::loop;

namespace {
const std::string kDefault = std::string(DYNAVINS_SOURCE_DIR) + "/data/vocabulary/default_vocabulary.bin";

BowVector bow_of(const VocabularyTree& voc, const cv::Mat& image) {
  Keyframe kf;
  kf.image = image;
  return voc.transform(compute_keyframe_descriptors(kf).descriptors);
}
}  // namespace

TEST_CASE("the shipped default vocabulary loads and scores the clip's frames", "[loop][vocabulary]") {
  REQUIRE(std::filesystem::exists(kDefault));
  CHECK(std::filesystem::file_size(kDefault) < 2'000'000);
  const VocabularyTree voc = VocabularyTree::load(kDefault);
  CHECK(voc.num_words() > 20000);
  const cv::Mat a = test::euroc_cam0_image(0), b = test::euroc_cam0_image(10);
  cv::Mat mirrored;
  cv::flip(a, mirrored, 1);  // the same texture, not the same place
  const BowVector va = bow_of(voc, a), vb = bow_of(voc, b), vm = bow_of(voc, mirrored);
  REQUIRE(!va.empty());
  CHECK(l1_score(va, va) == Approx(1.0));
  const double same_place = l1_score(va, vb), other = l1_score(va, vm);
  CHECK(same_place > 2 * other);
  WARN("default vocabulary: " << voc.num_words() << " words; score frame 0 vs 10 " << same_place
                              << ", vs frame 0 mirrored " << other);
}
