#include "pipeline/vio/process_memory.hpp"

#include <sys/resource.h>

namespace dynavins::pipeline {

double peak_rss_mb() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0.0;
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux reports kilobytes
}

}  // namespace dynavins::pipeline
