#pragma once
// A vocabulary tree of binary words (Nister and Stewenius 2006; as DBoW2 builds it for ORB, Galvez-Lopez and
// Tardos 2012), written here: hierarchical k-medians of 256-bit descriptors under the Hamming distance
// (k-means++ seeding from a fixed seed, majority-bit centres), leaves are the words, each weighted by its
// inverse document frequency over the training images. It turns a keyframe's descriptors into a TF-IDF
// bag-of-words vector for the keyframe database. Saved as a small versioned binary file.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "stages/loop/place/bow_vector.hpp"

namespace dynavins::loop {

struct VocabularyOptions {
  int branching = 10;       // k of each k-medians split
  int depth = 5;            // levels below the root: up to branching^depth words (10^5 by default)
  int max_iterations = 10;  // k-medians iterations per split (stops earlier when assignments settle)
  uint64_t seed = 42;       // k-means++ seeding; the same seed and data give the same tree
};

class VocabularyTree {
 public:
  /// One tree node; the root is node 0. Leaves (num_children == 0) carry a word id and its IDF weight.
  struct Node {
    std::array<uint8_t, 32> centre{};
    uint32_t first_child = 0;  // children are nodes [first_child, first_child + num_children)
    uint32_t num_children = 0;
    int32_t word = -1;
    float weight = 0.f;  // idf = ln(N / n_i), N training images, n_i of them containing the word
    bool operator==(const Node& o) const {
      return centre == o.centre && first_child == o.first_child && num_children == o.num_children && word == o.word &&
             weight == o.weight;
    }
  };

  VocabularyTree() = default;

  /// Trains on `descriptors`, one CV_8UC1 N x 32 matrix per training image (the images give the IDF).
  static VocabularyTree build(const std::vector<cv::Mat>& descriptors, const VocabularyOptions& opts = {});

  /// Word of one 32-byte descriptor: the leaf reached by descending to the nearest child centre.
  uint32_t word_of(const uint8_t* descriptor) const;

  /// TF-IDF bag of words of an image's descriptors (CV_8UC1 N x 32): weight_i = (n_i / n) * idf_i,
  /// L1-normalised (DBoW2's TF_IDF + L1 scheme).
  BowVector transform(const cv::Mat& descriptors) const;

  std::size_t num_words() const { return num_words_; }
  const std::vector<Node>& nodes() const { return nodes_; }
  bool empty() const { return nodes_.empty(); }
  bool operator==(const VocabularyTree& o) const {
    return branching_ == o.branching_ && depth_ == o.depth_ && num_words_ == o.num_words_ && nodes_ == o.nodes_;
  }

  /// Binary file: magic "DVVOCAB\0", version, branching, depth, node and word counts, then the nodes.
  /// Throws std::runtime_error naming the file (and the offset, for a bad or truncated file).
  void save(const std::string& path) const;
  static VocabularyTree load(const std::string& path);

  static constexpr uint32_t kFileVersion = 1;

 private:
  void index_words();  // fills idf_ from the leaves

  uint32_t branching_ = 0, depth_ = 0;
  std::size_t num_words_ = 0;
  std::vector<Node> nodes_;
  std::vector<float> idf_;  // word -> its leaf's weight
};

/// The vocabulary a `dynavins vocab` command builds: VocabularyTree::build over per-image descriptors,
/// logging its size.
VocabularyTree build_vocabulary(const std::vector<cv::Mat>& descriptors, const VocabularyOptions& opts = {});

}  // namespace dynavins::loop
