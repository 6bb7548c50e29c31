#pragma once
// Each subcommand of `dynavins` lives in its own bin/cmd_<name>.cpp and registers itself here.
// A subcommand's callback returns through CLI11; failures throw CommandError (exit code + message).

#include <stdexcept>
#include <string>

namespace CLI {
class App;
}

namespace dynavins::cli {

/// Thrown by a subcommand for a user-facing failure: main() logs the message and exits with `code`.
struct CommandError : std::runtime_error {
  explicit CommandError(const std::string& what, int code = 1) : std::runtime_error(what), exit_code(code) {}
  int exit_code;
};

void add_info_command(CLI::App& app);
void add_log_info_command(CLI::App& app);
void add_pipeline_check_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_convert_command(CLI::App& app);
void add_replay_command(CLI::App& app);
void add_sim_command(CLI::App& app);
void add_run_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_overlay_command(CLI::App& app);
void add_decode_command(CLI::App& app);
void add_live_command(CLI::App& app);
void add_vocab_command(CLI::App& app);

}  // namespace dynavins::cli
