#pragma once
// SIGINT / SIGTERM → graceful stop of a run: the first signal asks the sources to stop so that
// every queue drains and the outputs are written; a second one restores the default action,
// so an impatient user can still kill the process.

namespace dynavins::pipeline {

/// Installs the handler (idempotent). Call from main() before a run.
void install_interrupt_handler();
/// True once SIGINT or SIGTERM arrived.
bool interrupt_requested();
/// Forget a previous interrupt (tests, or a program that runs several pipelines).
void clear_interrupt();

}  // namespace dynavins::pipeline
