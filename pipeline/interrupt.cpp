#include "pipeline/interrupt.hpp"

#include <atomic>
#include <csignal>

namespace dynavins::pipeline {
namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "signal handler needs a lock-free flag");

extern "C" void on_signal(int sig) {
  if (g_interrupted.exchange(true)) std::signal(sig, SIG_DFL);  // second signal: default action
}

}  // namespace

void install_interrupt_handler() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

bool interrupt_requested() { return g_interrupted.load(); }

void clear_interrupt() { g_interrupted.store(false); }

}  // namespace dynavins::pipeline
