#pragma once
// The estimator's verdict on the tracks, fed back to the tracker (StereoTracker::set_rejected): the ids of
// the newest frame's features the robust BA rejected, and how many frames the estimator has finished.
// As fast as possible (rate 0) the tracker waits before each frame until the estimator has finished every
// earlier frame it can finish (TrackerInput::finishable_before: not those whose IMU lies behind an outage
// still to come), so the run stays repeatable and equal to the sequential driver's; in real time it takes
// the newest verdict there is and never waits. One writer thread, one reader thread.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <vector>

namespace dynavins::pipeline {

class RejectedTracksFeedback {
 public:
  /// Estimator thread: it has finished `frames_done` frames since the start; `ids` were rejected in the newest.
  void publish(int64_t frames_done, std::vector<int64_t> ids) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      frames_done_ = frames_done;
      ids_ = std::move(ids);
    }
    changed_.notify_all();
  }

  /// Estimator thread: it has finished `frames_done` frames without a new verdict (skipped ones).
  void finished(int64_t frames_done) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      frames_done_ = frames_done;
    }
    changed_.notify_all();
  }

  /// Estimator thread, at its end (or failure): no verdict follows, a waiting tracker goes on.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    changed_.notify_all();
  }

  /// Tracker thread: the newest ids once the estimator has finished `frames` frames or closed. False (and
  /// the newest ids there are) when `timeout` passed first.
  bool wait(int64_t frames, std::chrono::milliseconds timeout, std::vector<int64_t>* ids) {
    std::unique_lock<std::mutex> lock(mutex_);
    const bool ready = changed_.wait_for(lock, timeout, [&] { return closed_ || frames_done_ >= frames; });
    *ids = ids_;
    return ready;
  }

  /// Tracker thread: the newest ids, without waiting.
  std::vector<int64_t> latest() {
    std::lock_guard<std::mutex> lock(mutex_);
    return ids_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  int64_t frames_done_ = 0;
  std::vector<int64_t> ids_;
  bool closed_ = false;
};

}  // namespace dynavins::pipeline
