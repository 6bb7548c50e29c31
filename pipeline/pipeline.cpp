#include "pipeline/pipeline.hpp"

#include <pthread.h>
#include <sched.h>

#include <cstring>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "pipeline/interrupt.hpp"

namespace dynavins::pipeline {

Pipeline::~Pipeline() {
  if (!threads_.empty()) {
    stop_.abort();
    for (auto& t : threads_)
      if (t.joinable()) t.join();
  }
}

Pipeline::StageRecord& Pipeline::add_record(std::string name) {
  records_.push_back(std::make_unique<StageRecord>());
  records_.back()->name = std::move(name);
  return *records_.back();
}

void Pipeline::fail(const std::string& thread, const std::string& what) {
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    if (error_.empty()) {
      failed_thread_ = thread;
      error_ = what.empty() ? std::string("unknown error") : what;
    }
  }
  spdlog::error("{}: {}", thread, what);
  stop_.abort();
}

void Pipeline::launch(StageRecord& rec, std::function<void()> body, std::function<void()> close_outputs) {
  bodies_.push_back([this, &rec, body = std::move(body), close_outputs = std::move(close_outputs)]() {
    if (rec.realtime_priority > 0) {
      sched_param param{};
      param.sched_priority = rec.realtime_priority;
      const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
      (err == 0 ? realtime_granted_ : realtime_refused_).fetch_add(1, std::memory_order_relaxed);
      if (err != 0) spdlog::debug("{}: no real-time scheduling ({}); runs as a normal thread", rec.name, std::strerror(err));
    }
    try {
      body();
    } catch (const std::exception& e) {
      fail(rec.name, e.what());
    } catch (...) {
      fail(rec.name, "non-standard exception");
    }
    // Downstream learns about the end of stream (or sees the abort) only through this.
    try {
      if (close_outputs) close_outputs();
    } catch (const std::exception& e) {
      fail(rec.name, e.what());
    }
    rec.finished.store(true, std::memory_order_release);
    running_.fetch_sub(1, std::memory_order_acq_rel);
  });
}

void Pipeline::add_source(std::string name, std::function<void(const StopFlag&)> body,
                          std::function<void()> close_outputs) {
  StageRecord& rec = add_record(std::move(name));
  launch(rec, [this, body = std::move(body)]() { body(stop_); }, std::move(close_outputs));
}

void Pipeline::set_thread_realtime(const std::string& name, int priority) {
  if (priority < 1 || priority > 99) throw std::invalid_argument("set_thread_realtime: priority must be in [1, 99]");
  for (auto& r : records_)
    if (r->name == name) {
      r->realtime_priority = priority;
      return;
    }
  throw std::invalid_argument("set_thread_realtime: no thread named '" + name + "'");
}

RunReport Pipeline::run() {
  const int64_t t0 = steady_now_ns();
  running_.store(static_cast<int>(bodies_.size()), std::memory_order_release);
  threads_.reserve(bodies_.size());
  for (auto& body : bodies_) threads_.emplace_back(body);

  bool interrupted = false;
  while (running_.load(std::memory_order_acquire) > 0) {
    if (!interrupted && interrupt_requested()) {
      interrupted = true;
      spdlog::warn("interrupt: stopping sources and draining the queues (interrupt again to kill)");
      stop_.request_stop();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (auto& t : threads_) t.join();
  threads_.clear();

  RunReport report;
  report.wall_s = static_cast<double>(steady_now_ns() - t0) / 1e9;
  {
    std::lock_guard<std::mutex> lock(error_mutex_);
    report.ok = error_.empty();
    report.failed_thread = failed_thread_;
    report.error = error_;
  }
  report.interrupted = interrupted || (stop_.stop_requested() && report.ok);
  report.stages = stage_stats();
  report.queues = queue_stats();
  return report;
}

std::vector<StageStats> Pipeline::stage_stats() const {
  std::vector<StageStats> out;
  out.reserve(records_.size());
  for (const auto& r : records_) {
    StageStats s;
    s.name = r->name;
    s.processed = r->processed.load(std::memory_order_relaxed);
    s.process = r->process.summary();
    s.wait = r->wait.summary();
    s.finished = r->finished.load(std::memory_order_acquire);
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<QueueStats> Pipeline::queue_stats() const {
  std::vector<QueueStats> out;
  out.reserve(queues_.size());
  for (const auto& q : queues_) out.push_back(q->stats());
  return out;
}

}  // namespace dynavins::pipeline
