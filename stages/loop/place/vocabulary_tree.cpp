// Hierarchical binary k-medians, TF-IDF transform and the binary file (see vocabulary_tree.hpp).
#include "stages/loop/place/vocabulary_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "stages/loop/place/hamming.hpp"

namespace dynavins::loop {

namespace {

using Descriptor = std::array<uint8_t, kDescriptorBytes>;

/// Majority-bit centre of the descriptors `members` (ties give 0): the binary k-medians update.
Descriptor majority_centre(const std::vector<Descriptor>& all, const std::vector<uint32_t>& members) {
  std::array<uint32_t, kDescriptorBytes * 8> ones{};
  for (uint32_t m : members) {
    const Descriptor& d = all[m];
    for (int b = 0; b < kDescriptorBytes; ++b)
      for (int k = 0; k < 8; ++k) ones[b * 8 + k] += (d[b] >> k) & 1u;
  }
  Descriptor c{};
  for (int b = 0; b < kDescriptorBytes; ++b)
    for (int k = 0; k < 8; ++k)
      if (2 * ones[b * 8 + k] > members.size()) c[b] |= static_cast<uint8_t>(1u << k);
  return c;
}

class Builder {
 public:
  Builder(const std::vector<Descriptor>& all, const VocabularyOptions& opts, std::vector<VocabularyTree::Node>& nodes)
      : all_(all), opts_(opts), nodes_(nodes), rng_(opts.seed) {}

  std::size_t num_words() const { return num_words_; }

  /// Splits node `n` over the descriptors `members` (depth-first, so the tree depends only on seed and data).
  void split(uint32_t n, const std::vector<uint32_t>& members, int level) {
    const int k = opts_.branching;
    if (level >= opts_.depth || static_cast<int>(members.size()) <= k) return make_leaf(n);
    std::vector<Descriptor> centres = seed_centres(members);
    std::vector<int> assignment(members.size(), -1);
    std::vector<std::vector<uint32_t>> clusters;
    for (int it = 0; it < std::max(1, opts_.max_iterations); ++it) {
      bool changed = false;
      for (std::size_t i = 0; i < members.size(); ++i) {
        const int c = nearest(centres, all_[members[i]].data());
        if (c != assignment[i]) changed = true;
        assignment[i] = c;
      }
      clusters.assign(centres.size(), {});
      for (std::size_t i = 0; i < members.size(); ++i) clusters[assignment[i]].push_back(members[i]);
      if (!changed) break;
      for (std::size_t c = 0; c < centres.size(); ++c)
        if (!clusters[c].empty()) centres[c] = majority_centre(all_, clusters[c]);
    }
    // Empty clusters are dropped; one cluster only (identical descriptors) ends the branch.
    std::vector<std::size_t> kept;
    for (std::size_t c = 0; c < clusters.size(); ++c)
      if (!clusters[c].empty()) kept.push_back(c);
    if (kept.size() < 2) return make_leaf(n);
    const auto first = static_cast<uint32_t>(nodes_.size());
    nodes_[n].first_child = first;
    nodes_[n].num_children = static_cast<uint32_t>(kept.size());
    for (std::size_t c : kept) {
      VocabularyTree::Node child;
      child.centre = centres[c];
      nodes_.push_back(child);
    }
    for (std::size_t i = 0; i < kept.size(); ++i) split(first + static_cast<uint32_t>(i), clusters[kept[i]], level + 1);
  }

 private:
  void make_leaf(uint32_t n) { nodes_[n].word = static_cast<int32_t>(num_words_++); }

  static int nearest(const std::vector<Descriptor>& centres, const uint8_t* d) {
    int best = 0, best_d = std::numeric_limits<int>::max();
    for (std::size_t c = 0; c < centres.size(); ++c) {
      const int h = hamming_distance(centres[c].data(), d);
      if (h < best_d) best_d = h, best = static_cast<int>(c);
    }
    return best;
  }

  /// k-means++ (Arthur and Vassilvitskii 2007): each next centre drawn with probability ~ D(x)^2.
  std::vector<Descriptor> seed_centres(const std::vector<uint32_t>& members) {
    std::vector<Descriptor> centres;
    std::uniform_int_distribution<std::size_t> pick(0, members.size() - 1);
    centres.push_back(all_[members[pick(rng_)]]);
    std::vector<double> d2(members.size(), std::numeric_limits<double>::max());
    while (static_cast<int>(centres.size()) < opts_.branching) {
      double total = 0.0;
      for (std::size_t i = 0; i < members.size(); ++i) {
        const double h = hamming_distance(centres.back().data(), all_[members[i]].data());
        d2[i] = std::min(d2[i], h * h);
        total += d2[i];
      }
      if (total <= 0.0) break;  // all remaining descriptors coincide with a centre
      std::uniform_real_distribution<double> u(0.0, total);
      double r = u(rng_), acc = 0.0;
      std::size_t chosen = members.size() - 1;
      for (std::size_t i = 0; i < members.size(); ++i) {
        acc += d2[i];
        if (acc >= r && d2[i] > 0.0) {
          chosen = i;
          break;
        }
      }
      centres.push_back(all_[members[chosen]]);
    }
    return centres;
  }

  const std::vector<Descriptor>& all_;
  const VocabularyOptions& opts_;
  std::vector<VocabularyTree::Node>& nodes_;
  std::mt19937_64 rng_;
  std::size_t num_words_ = 0;
};

void check_descriptors(const cv::Mat& d, const char* where) {
  if (!d.empty() && (d.type() != CV_8UC1 || d.cols != kDescriptorBytes))
    throw std::invalid_argument(std::string(where) + ": descriptors must be CV_8UC1 with 32 columns");
}

// --- file ---------------------------------------------------------------------------------------
constexpr char kMagic[8] = {'D', 'V', 'V', 'O', 'C', 'A', 'B', '\0'};
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 4 + 8 + 8;
constexpr std::size_t kNodeBytes = kDescriptorBytes + 4 + 4 + 4 + 4;

template <typename T>
void put(std::string& buf, const T& v) {
  buf.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

class Reader {
 public:
  Reader(const std::string& path, const std::string& data) : path_(path), data_(data) {}
  template <typename T>
  T get(const char* what) {
    T v;
    if (offset_ + sizeof(T) > data_.size()) fail("truncated while reading " + std::string(what));
    std::memcpy(&v, data_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return v;
  }
  void bytes(uint8_t* out, std::size_t n, const char* what) {
    if (offset_ + n > data_.size()) fail("truncated while reading " + std::string(what));
    std::memcpy(out, data_.data() + offset_, n);
    offset_ += n;
  }
  [[noreturn]] void fail(const std::string& why) const { fail_at(why, offset_); }
  [[noreturn]] void fail_at(const std::string& why, std::size_t offset) const {
    throw std::runtime_error("vocabulary file '" + path_ + "': " + why + " at offset " + std::to_string(offset) +
                             " (file size " + std::to_string(data_.size()) + " bytes)");
  }
  std::size_t offset() const { return offset_; }
  std::size_t size() const { return data_.size(); }

 private:
  const std::string& path_;
  const std::string& data_;
  std::size_t offset_ = 0;
};

}  // namespace

VocabularyTree VocabularyTree::build(const std::vector<cv::Mat>& descriptors, const VocabularyOptions& opts) {
  if (opts.branching < 2 || opts.depth < 1)
    throw std::invalid_argument("VocabularyTree::build: branching >= 2, depth >= 1");
  std::vector<Descriptor> all;
  for (const cv::Mat& d : descriptors) {
    check_descriptors(d, "VocabularyTree::build");
    for (int r = 0; r < d.rows; ++r) {
      Descriptor x;
      std::memcpy(x.data(), d.ptr<uint8_t>(r), kDescriptorBytes);
      all.push_back(x);
    }
  }
  if (all.empty()) throw std::invalid_argument("VocabularyTree::build: no training descriptors");

  VocabularyTree tree;
  tree.branching_ = static_cast<uint32_t>(opts.branching);
  tree.depth_ = static_cast<uint32_t>(opts.depth);
  tree.nodes_.emplace_back();  // root, centre unused
  std::vector<uint32_t> members(all.size());
  for (std::size_t i = 0; i < all.size(); ++i) members[i] = static_cast<uint32_t>(i);
  Builder builder(all, opts, tree.nodes_);
  builder.split(0, members, 0);
  tree.num_words_ = builder.num_words();

  // IDF over the training images: idf_i = ln(N / n_i) (DBoW2's TF_IDF weighting).
  std::vector<uint32_t> leaf_of_word(tree.num_words_);
  for (uint32_t n = 0; n < tree.nodes_.size(); ++n)
    if (tree.nodes_[n].word >= 0) leaf_of_word[tree.nodes_[n].word] = n;
  std::vector<uint32_t> images_with(tree.num_words_, 0);
  std::vector<int64_t> last_image(tree.num_words_, -1);
  for (std::size_t im = 0; im < descriptors.size(); ++im)
    for (int r = 0; r < descriptors[im].rows; ++r) {
      const uint32_t w = tree.word_of(descriptors[im].ptr<uint8_t>(r));
      if (last_image[w] != static_cast<int64_t>(im)) last_image[w] = static_cast<int64_t>(im), ++images_with[w];
    }
  const double n_images = static_cast<double>(descriptors.size());
  for (std::size_t w = 0; w < tree.num_words_; ++w)
    tree.nodes_[leaf_of_word[w]].weight =
        images_with[w] > 0 ? static_cast<float>(std::log(n_images / images_with[w])) : 0.f;
  tree.index_words();
  return tree;
}

void VocabularyTree::index_words() {
  idf_.assign(num_words_, 0.f);
  for (const Node& node : nodes_)
    if (node.word >= 0) idf_[node.word] = node.weight;
}

uint32_t VocabularyTree::word_of(const uint8_t* descriptor) const {
  if (nodes_.empty()) throw std::logic_error("VocabularyTree::word_of: empty vocabulary");
  uint32_t n = 0;
  while (nodes_[n].num_children > 0) {
    const Node& node = nodes_[n];
    uint32_t best = node.first_child;
    int best_d = std::numeric_limits<int>::max();
    for (uint32_t c = node.first_child; c < node.first_child + node.num_children; ++c) {
      const int h = hamming_distance(nodes_[c].centre.data(), descriptor);
      if (h < best_d) best_d = h, best = c;
    }
    n = best;
  }
  return static_cast<uint32_t>(nodes_[n].word);
}

BowVector VocabularyTree::transform(const cv::Mat& descriptors) const {
  check_descriptors(descriptors, "VocabularyTree::transform");
  BowVector v;
  if (descriptors.rows == 0) return v;
  std::vector<uint32_t> words(descriptors.rows);
  for (int r = 0; r < descriptors.rows; ++r) words[r] = word_of(descriptors.ptr<uint8_t>(r));
  std::sort(words.begin(), words.end());
  double total = 0.0;
  const double n = descriptors.rows;
  for (std::size_t i = 0; i < words.size();) {
    std::size_t j = i;
    while (j < words.size() && words[j] == words[i]) ++j;
    v.push_back({words[i], static_cast<double>(j - i) / n});  // tf, idf applied below
    i = j;
  }
  BowVector out;
  out.reserve(v.size());
  for (const BowEntry& e : v) {
    const double w = e.weight * idf_[e.word];
    if (w > 0.0) out.push_back({e.word, w}), total += w;
  }
  if (total <= 0.0) return {};
  for (BowEntry& e : out) e.weight /= total;  // L1 normalisation
  return out;
}

void VocabularyTree::save(const std::string& path) const {
  std::string buf;
  buf.reserve(kHeaderBytes + nodes_.size() * kNodeBytes);
  buf.append(kMagic, sizeof(kMagic));
  put(buf, kFileVersion);
  put(buf, branching_);
  put(buf, depth_);
  put(buf, static_cast<uint64_t>(nodes_.size()));
  put(buf, static_cast<uint64_t>(num_words_));
  for (const Node& n : nodes_) {
    buf.append(reinterpret_cast<const char*>(n.centre.data()), kDescriptorBytes);
    put(buf, n.first_child);
    put(buf, n.num_children);
    put(buf, n.word);
    put(buf, n.weight);
  }
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw std::runtime_error("vocabulary file '" + path + "': cannot open for writing");
  f.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  if (!f) throw std::runtime_error("vocabulary file '" + path + "': write failed");
}

VocabularyTree VocabularyTree::load(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("vocabulary file '" + path + "': cannot open");
  std::string data((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  Reader r(path, data);
  char magic[8];
  r.bytes(reinterpret_cast<uint8_t*>(magic), sizeof(magic), "the magic");
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) r.fail_at("not a DynaVINS vocabulary (bad magic)", 0);
  const auto version = r.get<uint32_t>("the version");
  if (version != kFileVersion)
    r.fail_at("version " + std::to_string(version) + ", expected " + std::to_string(kFileVersion), 8);
  VocabularyTree t;
  t.branching_ = r.get<uint32_t>("the branching");
  t.depth_ = r.get<uint32_t>("the depth");
  const auto num_nodes = r.get<uint64_t>("the node count");
  const auto num_words = r.get<uint64_t>("the word count");
  if (num_nodes == 0 || num_words == 0 || num_words > num_nodes) r.fail("bad node/word counts");
  const std::size_t expected = kHeaderBytes + num_nodes * kNodeBytes;
  if (num_nodes > (data.size() / kNodeBytes) + 1 || data.size() < expected)
    r.fail_at("truncated: " + std::to_string(num_nodes) + " nodes need " + std::to_string(expected) + " bytes",
              data.size());
  if (data.size() > expected) r.fail_at("trailing bytes after the last node", expected);
  t.num_words_ = num_words;
  t.nodes_.resize(num_nodes);
  std::vector<bool> word_seen(num_words, false);
  for (std::size_t i = 0; i < num_nodes; ++i) {
    const std::size_t at = r.offset();
    Node& n = t.nodes_[i];
    r.bytes(n.centre.data(), kDescriptorBytes, "a node centre");
    n.first_child = r.get<uint32_t>("a node's first child");
    n.num_children = r.get<uint32_t>("a node's child count");
    n.word = r.get<int32_t>("a node's word");
    n.weight = r.get<float>("a node's weight");
    const bool leaf = n.num_children == 0;
    if (leaf != (n.word >= 0)) r.fail_at("node " + std::to_string(i) + ": leaf/word mismatch", at);
    if (!leaf && (n.first_child <= i || static_cast<uint64_t>(n.first_child) + n.num_children > num_nodes))
      r.fail_at("node " + std::to_string(i) + ": children out of range", at);
    if (leaf) {
      if (static_cast<uint64_t>(n.word) >= num_words || word_seen[n.word])
        r.fail_at("node " + std::to_string(i) + ": bad word id " + std::to_string(n.word), at);
      word_seen[n.word] = true;
    }
    if (!std::isfinite(n.weight) || n.weight < 0.f) r.fail_at("node " + std::to_string(i) + ": bad weight", at);
  }
  if (std::find(word_seen.begin(), word_seen.end(), false) != word_seen.end())
    r.fail_at("some word ids have no leaf", kHeaderBytes);
  t.index_words();
  return t;
}

VocabularyTree build_vocabulary(const std::vector<cv::Mat>& descriptors, const VocabularyOptions& opts) {
  std::size_t n = 0;
  for (const cv::Mat& d : descriptors) n += static_cast<std::size_t>(d.rows);
  VocabularyTree t = VocabularyTree::build(descriptors, opts);
  spdlog::info("vocabulary: {} words ({} nodes) from {} descriptors of {} images, branching {}, depth {}",
               t.num_words(), t.nodes().size(), n, descriptors.size(), opts.branching, opts.depth);
  return t;
}

}  // namespace dynavins::loop
