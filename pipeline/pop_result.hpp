#pragma once

namespace dynavins::pipeline {

/// Outcome of a consumer's wait on a queue.
enum class PopResult {
  Item,     ///< an item was taken
  Timeout,  ///< nothing arrived within the timeout; the producer is still open
  Closed,   ///< the producer(s) closed and everything was taken: end of stream
  Aborted,  ///< the run was aborted; stop now
};

/// An item with the moment it entered its queue, so the consumer can report queue wait.
template <typename T>
struct Stamped {
  T value;
  int64_t enqueued_ns = 0;
};

}  // namespace dynavins::pipeline
