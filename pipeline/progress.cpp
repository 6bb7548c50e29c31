#include "pipeline/progress.hpp"

#include <cstdio>
#include <unistd.h>

#include <spdlog/spdlog.h>

#include "pipeline/clock.hpp"

namespace dynavins::pipeline {

Progress::Progress(std::string label, double log_every_s)
    : label_(std::move(label)),
      log_every_s_(log_every_s),
      tty_(isatty(STDERR_FILENO) == 1),
      start_ns_(steady_now_ns()),
      last_print_ns_(start_ns_) {}  // first line after one interval, not at 0%

void Progress::update(double fraction, const std::string& detail) {
  const int64_t now = steady_now_ns();
  const double since_print = static_cast<double>(now - last_print_ns_) / 1e9;
  if (since_print < (tty_ ? 0.25 : log_every_s_)) return;
  last_print_ns_ = now;
  const double elapsed = static_cast<double>(now - start_ns_) / 1e9;
  const double eta = fraction > 1e-6 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  if (tty_) {
    std::fprintf(stderr, "\r%s %5.1f%%  %s  ETA %.0f s   ", label_.c_str(), 100.0 * fraction, detail.c_str(), eta);
    std::fflush(stderr);
  } else {
    spdlog::info("{} {:.1f}%  {}  ETA {:.0f} s", label_, 100.0 * fraction, detail, eta);
  }
}

void Progress::done(const std::string& detail) {
  if (tty_ && last_print_ns_ != start_ns_) std::fprintf(stderr, "\n");
  spdlog::info("{} done: {}", label_, detail);
}

}  // namespace dynavins::pipeline
