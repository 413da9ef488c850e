#pragma once
// The command-line and configuration conventions every kestrel tool and process follows.
//
// * Options are declared with CLI11; every option has a default that --help shows.
// * `--config FILE` reads the same options from an INI file (key = long option name without
//   dashes, `[section]` = subcommand); an unknown key or a bad value is an error naming it.
//   `--print-config` prints the effective configuration in that format and exits.
// * `-v` / `-q` raise or lower the log level; logs go to stderr, one line each.
// * Errors end the tool with one line "kestrel-<name>: error: <what>" and an ExitCode
//   (common/error.h): usage problems exit kExitUsage, InputError exits kExitBadInput, any
//   other exception kExitFailure.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace kestrel::cli {

/// A CLI11 app named `kestrel-<name>` with --config, --print-config, -v and -q.
class App : public CLI::App {
 public:
  App(const std::string& name, const std::string& description);
  /// Parses, configures logging and calls `body`; returns the process exit code.
  int run(int argc, char** argv, const std::function<int()>& body);

 private:
  int verbosity_ = 0;
  bool print_config_ = false;
};

/// Validator: a number strictly greater than zero.
extern const CLI::Validator Positive;

}  // namespace kestrel::cli
