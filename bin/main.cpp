// dynavins: one program, one subcommand per job (CLI11). Thin: parse, wire, run.
#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "bin/commands.hpp"

int main(int argc, char** argv) {
  // Logs on stderr, results on stdout: `dynavins eval ... > metrics.txt` stays clean.
  spdlog::set_default_logger(spdlog::stderr_color_mt("dynavins"));
  CLI::App app{"DynaVINS: visual-inertial SLAM that keeps its pose when most of the image moves.\n"
               "Run `dynavins <subcommand> --help` for the options of each."};
  app.set_version_flag("--version", std::string(DYNAVINS_VERSION));
  app.require_subcommand(1);
  app.fallthrough();  // --log-level may also follow the subcommand

  std::string log_level = "info";
  app.add_option("--log-level", log_level, "Log verbosity")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}))
      ->capture_default_str();
  // Applied before any subcommand's callback runs.
  app.parse_complete_callback([&log_level] { spdlog::set_level(spdlog::level::from_str(log_level)); });

  dynavins::cli::add_info_command(app);
  dynavins::cli::add_log_info_command(app);
  dynavins::cli::add_pipeline_check_command(app);
  dynavins::cli::add_sim_command(app);
  dynavins::cli::add_convert_command(app);
  dynavins::cli::add_replay_command(app);
  dynavins::cli::add_eval_command(app);
  dynavins::cli::add_run_command(app);
  dynavins::cli::add_compare_command(app);
  dynavins::cli::add_overlay_command(app);
  dynavins::cli::add_decode_command(app);
  dynavins::cli::add_live_command(app);
  dynavins::cli::add_vocab_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const dynavins::cli::CommandError& e) {
    spdlog::error("{}", e.what());
    return e.exit_code;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
