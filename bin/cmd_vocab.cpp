// `dynavins vocab --euroc DIR [--euroc DIR ...] [--every N ...] [--branching 10] [--depth 5] [--seed 42] --out FILE`:
// trains the loop closer's vocabulary tree (stages/loop/place/vocabulary_tree.hpp) on the cam0 images of
// EuRoC folders (mav0/cam0/data/*.png, in name order, every N-th: one N for all folders or one per folder), with the
// descriptors the loop stage computes on a keyframe (compute_keyframe_descriptors with extra corners only: no tracked
// points here). Deterministic: the same folders and options give the same file, byte for byte. The file is written to
// FILE.partial and renamed when complete.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"
#include "stages/loop/place/keyframe_descriptors.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"

namespace dynavins::cli {
namespace {

namespace fs = std::filesystem;

struct VocabOptions {
  std::vector<std::string> euroc;
  std::vector<int> every{1};  // one for all folders, or one per folder
  loop::VocabularyOptions tree;
  std::string out;
};

/// cam0 images of an EuRoC folder (DIR/mav0/cam0/data or DIR/cam0/data when DIR is mav0 itself), by name.
std::vector<fs::path> cam0_images(const std::string& dir) {
  fs::path data = fs::path(dir) / "mav0" / "cam0" / "data";
  if (!fs::is_directory(data)) data = fs::path(dir) / "cam0" / "data";
  if (!fs::is_directory(data))
    throw CommandError(fmt::format("{}: no mav0/cam0/data folder (not an EuRoC ASL folder)", dir), 2);
  std::vector<fs::path> images;
  for (const auto& e : fs::directory_iterator(data))
    if (e.is_regular_file() && e.path().extension() == ".png") images.push_back(e.path());
  std::sort(images.begin(), images.end());
  if (images.empty()) throw CommandError(fmt::format("{}: no .png images in {}", dir, data.string()), 2);
  return images;
}

void run_vocab(const VocabOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<cv::Mat> descriptors;
  std::size_t total = 0;
  if (o.every.size() != 1 && o.every.size() != o.euroc.size())
    throw CommandError(fmt::format("--every: {} values for {} --euroc folders (give one, or one per folder)",
                                   o.every.size(), o.euroc.size()),
                       2);
  for (std::size_t f = 0; f < o.euroc.size(); ++f) {
    const std::string& dir = o.euroc[f];
    const auto every = static_cast<std::size_t>(o.every.size() == 1 ? o.every[0] : o.every[f]);
    const std::vector<fs::path> images = cam0_images(dir);
    std::size_t used = 0, before = total;
    for (std::size_t i = 0; i < images.size(); i += every) {
      Keyframe kf;
      kf.image = cv::imread(images[i].string(), cv::IMREAD_GRAYSCALE);
      if (kf.image.empty()) throw CommandError(fmt::format("{}: cannot read the image", images[i].string()), 2);
      loop::KeyframeDescriptors d = loop::compute_keyframe_descriptors(kf);
      ++used;
      if (d.descriptors.rows == 0) continue;
      total += static_cast<std::size_t>(d.descriptors.rows);
      descriptors.push_back(d.descriptors);
    }
    spdlog::info("{}: {} of {} images, {} descriptors", dir, used, images.size(), total - before);
  }
  if (descriptors.empty()) throw CommandError("no descriptors in the images given: nothing to train on", 2);
  const auto t1 = std::chrono::steady_clock::now();
  const loop::VocabularyTree tree = loop::build_vocabulary(descriptors, o.tree);
  const auto t2 = std::chrono::steady_clock::now();

  const std::string partial = o.out + ".partial";
  try {
    if (fs::path(o.out).has_parent_path()) fs::create_directories(fs::path(o.out).parent_path());
    tree.save(partial);
  } catch (const std::exception& e) {
    fs::remove(partial);
    throw CommandError(std::string(e.what()) + " (nothing written to " + o.out + ")", 2);
  }
  fs::rename(partial, o.out);
  const double desc_s = std::chrono::duration<double>(t1 - t0).count();
  const double build_s = std::chrono::duration<double>(t2 - t1).count();
  std::cout << fmt::format(
      "vocabulary {}: {} words, {} nodes, {} bytes; {} descriptors of {} images (branching {}, depth {}, seed {}); "
      "descriptors {:.2f} s, tree {:.2f} s\n",
      o.out, tree.num_words(), tree.nodes().size(), fs::file_size(o.out), total, descriptors.size(), o.tree.branching,
      o.tree.depth, o.tree.seed, desc_s, build_s);
}

}  // namespace

void add_vocab_command(CLI::App& app) {
  auto o = std::make_shared<VocabOptions>();
  auto* cmd =
      app.add_subcommand("vocab", "Train the loop closer's ORB vocabulary tree on the cam0 images of EuRoC folders");
  cmd->add_option("--euroc", o->euroc, "EuRoC ASL folder (holding mav0/); repeatable")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--every", o->every, "Use every N-th image: one N for all folders, or one per --euroc in order")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--branching", o->tree.branching, "Children per tree node")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  cmd->add_option("--depth", o->tree.depth, "Levels below the root")->check(CLI::Range(1, 8))->capture_default_str();
  cmd->add_option("--seed", o->tree.seed, "k-means++ seed")->capture_default_str();
  cmd->add_option("--out", o->out, "Vocabulary file to write")->required();
  cmd->callback([o] { run_vocab(*o); });
}

}  // namespace dynavins::cli
