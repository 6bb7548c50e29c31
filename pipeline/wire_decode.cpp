#include "pipeline/wire_decode.hpp"

#include <functional>
#include <map>

namespace dynavins::pipeline {
namespace {

/// A bounds-checked walk over an encoded payload (big-endian, as lcm encodes).
class WireCursor {
 public:
  WireCursor(const uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  /// Skips `n` bytes of fixed-size fields; false when fewer are left.
  bool skip(std::size_t n, const char* field) {
    if (n > left()) return fail(std::string(field) + " needs " + std::to_string(n) + " bytes, " + std::to_string(left()) + " left");
    pos_ += n;
    return true;
  }
  /// Reads a count field (int32) and checks that `count` elements of at least `min_element_bytes`
  /// each fit in what follows.
  bool count(int32_t& out, std::size_t min_element_bytes, const char* field) {
    if (!read_i32(out, field)) return false;
    if (out < 0) return fail(std::string(field) + " is negative (" + std::to_string(out) + ")");
    const uint64_t need = static_cast<uint64_t>(out) * min_element_bytes;
    if (need > left())
      return fail(std::string(field) + " " + std::to_string(out) + " needs " + std::to_string(need) + " bytes, " +
                  std::to_string(left()) + " left");
    return true;
  }
  /// A string: int32 length counting its terminating 0, at least 1, then that many bytes.
  bool string(const char* field) {
    int32_t n = 0;
    if (!read_i32(n, field)) return false;
    if (n < 1) return fail(std::string(field) + " has length " + std::to_string(n) + " (at least 1: its terminating 0)");
    return skip(static_cast<std::size_t>(n), field);
  }
  const std::string& problem() const { return problem_; }
  std::size_t position() const { return pos_; }

 private:
  std::size_t left() const { return size_ - pos_; }
  bool read_i32(int32_t& out, const char* field) {
    if (left() < 4) return fail(std::string(field) + " needs 4 bytes, " + std::to_string(left()) + " left");
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | data_[pos_ + i];
    out = static_cast<int32_t>(v);
    pos_ += 4;
    return true;
  }
  bool fail(const std::string& what) {
    if (problem_.empty()) problem_ = what + " (at byte " + std::to_string(pos_) + ")";
    return false;
  }

  const uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string problem_;
};

// Layouts after the fingerprint, field by field as in lcm_types/*.lcm (fixed-size fields skipped).
// Fixed encoded sizes of the element types used in arrays:
constexpr std::size_t kPoseBytes = 8 + 1 + 3 * 8 + 4 * 8 + 3 * 8;       // pose_t
constexpr std::size_t kFeatureBytes = 8 + 4 + 4 + 3 * 8 + 4 + 4 + 1;    // weighted_feature_t
constexpr std::size_t kMinStringBytes = 4 + 1;                          // length + terminating 0
constexpr std::size_t kMinHypothesisBytes = 4 + 3 * 8 + 4 * 8 + 4;      // loop_hypothesis_t, no loops
constexpr std::size_t kMinStageBytes = kMinStringBytes + 8 + 5 * 4;      // stage_stats_t
constexpr std::size_t kMinQueueBytes = kMinStringBytes + 3 * 4 + 3 * 8;  // queue_stats_t

bool walk_image(WireCursor& c) {  // image_t: utime, width, height, encoding, size, data[size]
  int32_t size = 0;
  return c.skip(8 + 4 + 4 + 1, "image_t header") && c.count(size, 1, "image_t.size") &&
         c.skip(static_cast<std::size_t>(size), "image_t.data");
}

bool walk_stereo(WireCursor& c) {  // stereo_image_t: utime, seq, left, right
  return c.skip(8 + 8, "stereo_image_t header") && walk_image(c) && walk_image(c);
}

bool walk_feature_set(WireCursor& c) {  // weighted_feature_set_t: utime, num_features, features
  int32_t n = 0;
  return c.skip(8, "weighted_feature_set_t.utime") && c.count(n, kFeatureBytes, "weighted_feature_set_t.num_features") &&
         c.skip(static_cast<std::size_t>(n) * kFeatureBytes, "weighted_feature_set_t.features");
}

bool walk_path(WireCursor& c) {  // path_t: utime, num_poses, poses
  int32_t n = 0;
  return c.skip(8, "path_t.utime") && c.count(n, kPoseBytes, "path_t.num_poses") &&
         c.skip(static_cast<std::size_t>(n) * kPoseBytes, "path_t.poses");
}

bool walk_hypotheses(WireCursor& c) {  // loop_hypotheses_t: utime, group_first_utime, group_size, hypotheses
  int32_t n = 0;
  if (!c.skip(8 + 8 + 4, "loop_hypotheses_t header") ||
      !c.count(n, kMinHypothesisBytes, "loop_hypotheses_t.num_hypotheses"))
    return false;
  for (int32_t i = 0; i < n; ++i) {  // loop_hypothesis_t: weight, position, orientation, num_loops, 2 arrays
    int32_t loops = 0;
    if (!c.skip(4 + 3 * 8 + 4 * 8, "loop_hypothesis_t header") || !c.count(loops, 2 * 8, "loop_hypothesis_t.num_loops") ||
        !c.skip(static_cast<std::size_t>(loops) * 2 * 8, "loop_hypothesis_t utimes"))
      return false;
  }
  return true;
}

bool walk_status(WireCursor& c) {  // status_t: utime, status, reason, frames, resets
  return c.skip(8 + 1, "status_t header") && c.string("status_t.reason") && c.skip(8 + 8, "status_t counts");
}

bool walk_stats(WireCursor& c) {  // pipeline_stats_t: utime, wall_s, realtime_factor, stages, queues
  int32_t n = 0;
  if (!c.skip(8 + 8 + 8, "pipeline_stats_t header") || !c.count(n, kMinStageBytes, "pipeline_stats_t.num_stages"))
    return false;
  for (int32_t i = 0; i < n; ++i)
    if (!c.string("stage_stats_t.name") || !c.skip(8 + 5 * 4, "stage_stats_t numbers")) return false;
  if (!c.count(n, kMinQueueBytes, "pipeline_stats_t.num_queues")) return false;
  for (int32_t i = 0; i < n; ++i)
    if (!c.string("queue_stats_t.name") || !c.skip(3 * 4 + 3 * 8, "queue_stats_t numbers")) return false;
  return true;
}

}  // namespace

std::string wire_length_problem(const std::string& type_name, const uint8_t* data, std::size_t size) {
  static const std::map<std::string, std::function<bool(WireCursor&)>> kWalkers = {
      {"image_t", walk_image},
      {"stereo_image_t", walk_stereo},
      {"weighted_feature_set_t", walk_feature_set},
      {"path_t", walk_path},
      {"loop_hypotheses_t", walk_hypotheses},
      {"status_t", walk_status},
      {"pipeline_stats_t", walk_stats},
  };
  const auto it = kWalkers.find(type_name);
  if (it == kWalkers.end()) return {};
  WireCursor c(data, size);
  if (!c.skip(8, "fingerprint") || !it->second(c)) return c.problem();
  // A walk that ends elsewhere than the payload's end: trailing bytes (or a layout here out of step
  // with lcm_types/, which the round-trip test catches).
  if (c.position() != size)
    return "payload has " + std::to_string(size - c.position()) + " bytes after the end of its " + type_name;
  return {};
}

}  // namespace dynavins::pipeline
