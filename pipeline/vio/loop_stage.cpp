#include "pipeline/vio/loop_stage.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "stages/common/camera_model.hpp"
#include "stages/loop/loop_closer.hpp"
#include "stages/loop/place/vocabulary_tree.hpp"

namespace dynavins::pipeline {

namespace {
/// CPU time of the calling thread [ms].
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}
}  // namespace

LoopStage::LoopStage(loop::LoopMode mode, const std::string& vocabulary_path, std::shared_ptr<const CameraModel> camera)
    : mode_(mode), vocabulary_path_(vocabulary_path) {
  std::shared_ptr<const loop::VocabularyTree> vocabulary;
  try {
    vocabulary = std::make_shared<const loop::VocabularyTree>(loop::VocabularyTree::load(vocabulary_path));
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("loop closure vocabulary: ") + e.what());
  }
  loop::LoopCloserOptions o;
  o.mode = mode;
  loop::Undistort undistort;
  if (camera)
    undistort = [camera](const Eigen::Vector2d& px) -> Eigen::Vector2d {
      const Eigen::Vector3d b = camera->lift(px);
      return b.head<2>() / b.z();
    };
  closer_ = std::make_unique<loop::LoopCloser>(std::move(vocabulary), o, std::move(undistort));
}

LoopStage::~LoopStage() = default;

void LoopStage::account(const loop::LoopCloserOutput& out, double ms) {
  ms_sum_ += ms;
  ms_max_ = std::max(ms_max_, ms);
  descriptors_ms_sum_ += out.timing.descriptors_ms;
  query_ms_sum_ += out.timing.query_ms;
  verification_ms_sum_ += out.timing.verification_ms;
  if (out.optimized) {
    opt_ms_max_ = std::max(opt_ms_max_, out.timing.optimization_ms);
    opt_ms_sum_ += out.timing.optimization_ms;
    spdlog::debug("loop: optimised at t = {} ns ({:.1f} ms)", out.t_ns, out.timing.optimization_ms);
  }
  if (on_output) on_output(out);
}

void LoopStage::process(Keyframe keyframe) {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = thread_cpu_ms();
  const loop::LoopCloserOutput out = closer_->add_keyframe(keyframe);
  cpu_ms_sum_ += thread_cpu_ms() - cpu0;
  ++keyframes_;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  keyframe_ms_.push_back(ms);
  account(out, ms);
}

void LoopStage::finish() {
  const auto t0 = std::chrono::steady_clock::now();
  const loop::LoopCloserOutput out = closer_->finish();
  account(out, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  spdlog::info("loop: {} keyframes, {} verified loops, {} groups, {} optimisations ({})", keyframes_,
               closer_->loops().size(), closer_->groups().size(), closer_->num_optimizations(),
               loop::loop_mode_name(mode_));
}

LoopRunSummary LoopStage::summary() const {
  LoopRunSummary s;
  s.mode = mode_;
  s.vocabulary = vocabulary_path_;
  s.keyframes = keyframes_;
  s.keyframes_dropped = dropped;
  s.groups = static_cast<int64_t>(closer_->groups().size());
  s.optimizations = closer_->num_optimizations();
  s.keyframe_ms_mean = keyframes_ > 0 ? ms_sum_ / static_cast<double>(keyframes_) : 0.0;
  s.keyframe_cpu_ms_mean = keyframes_ > 0 ? cpu_ms_sum_ / static_cast<double>(keyframes_) : 0.0;
  s.keyframe_ms_max = ms_max_;
  if (!keyframe_ms_.empty()) {
    std::vector<double> sorted = keyframe_ms_;
    const auto k = static_cast<std::size_t>(0.95 * static_cast<double>(sorted.size() - 1) + 0.5);
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
    s.keyframe_ms_p95 = sorted[k];
    const auto n = static_cast<double>(keyframe_ms_.size());
    s.descriptors_ms_mean = descriptors_ms_sum_ / n;
    s.query_ms_mean = query_ms_sum_ / n;
    s.verification_ms_mean = verification_ms_sum_ / n;
  }
  if (closer_->num_optimizations() > 0) s.optimization_ms_mean = opt_ms_sum_ / closer_->num_optimizations();
  s.optimization_ms_max = opt_ms_max_;
  s.memory_bytes = closer_->memory_bytes();
  s.keyframes_released = static_cast<int64_t>(closer_->num_released());
  s.correction_applied = closer_->num_optimizations() > 0 && !closer_->last_result().correction_skipped;
  s.corrections = closer_->keyframe_corrections();
  s.loops = closer_->loops();
  if (closer_->num_optimizations() > 0) s.rows = loop::loop_report(closer_->optimizer(), closer_->last_result());
  if (s.rows.size() != s.loops.size()) {  // never optimised (or off): the loops without weights
    s.rows.clear();
    for (const VerifiedLoop& l : s.loops) {
      loop::LoopReportRow r;
      r.query_t_ns = l.query_t_ns;
      r.match_t_ns = l.match_t_ns;
      r.inliers = l.inliers;
      s.rows.push_back(r);
    }
  }
  return s;
}

}  // namespace dynavins::pipeline
