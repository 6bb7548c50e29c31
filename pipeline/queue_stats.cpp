#include "pipeline/queue_stats.hpp"

namespace dynavins::pipeline {

const char* to_string(Backpressure policy) {
  switch (policy) {
    case Backpressure::Block: return "block";
    case Backpressure::DropOldest: return "drop-oldest";
    case Backpressure::DropNewest: return "drop-newest";
  }
  return "?";
}

}  // namespace dynavins::pipeline
