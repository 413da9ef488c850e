#pragma once
// The command-line and configuration conventions every kestrel tool and process follows.
//
// * Options are declared with CLI11; every option has a default that --help shows (run() takes
//   an option's value at the start as its default string when the tool gave none, and shows
//   none when the option's own checks reject that value: "" for a choice, 0 for a length,
//   meaning "not set").
// * `--config FILE` reads options from an INI file; `--print-config` prints the options that
//   were set in that form, the others as comments with their defaults, and exits
//   (common/cli_config.h). Read back, the printed file gives the same configuration and prints
//   the same text; --help, --config and --print-config are never in it.
// * Values are checked as they are parsed: a floating-point option takes finite numbers only
//   (nan, inf, 1e999 are usage errors), and a failed range check states its bounds readably
//   ("must be a number in [0, 1e+09]", "must be a number >= 0"), not with CLI11's 309 digits.
// * `-v` / `-q` raise or lower the log level; logs go to stderr, one line each.
// * Errors end the tool with one line "kestrel-<name>: error: <what>" and an ExitCode
//   (common/error.h): a bad option value or configuration file exits kExitUsage (a file's
//   error names it and the line), InputError kExitBadInput, UnavailableError kExitUnavailable,
//   any other exception kExitFailure. Bytes that do not print are escaped in that line
//   (printable()), so a binary file's bytes never reach the terminal.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <string_view>
#include <optional>
#include <vector>

#include "common/camera.h"
#include "common/cli_config.h"

namespace kestrel::cli {

/// A CLI11 app named `kestrel-<name>` with --config, --print-config, -v and -q.
class App : public CLI::App {
 public:
  App(const std::string& name, const std::string& description);
  /// Parses, configures logging and calls `body`; returns the process exit code.
  int run(int argc, char** argv, const std::function<int()>& body);

 private:
  // Once, before parsing: default strings, readable range errors, finiteness, and the
  // recording of each value as typed (for --print-config).
  void prepare_options();
  std::string config_source() const;

  int verbosity_ = 0;
  bool print_config_ = false;
  GivenValues given_;
};

/// Validator: a finite number strictly greater than zero.
extern const CLI::Validator Positive;
/// Validator: a finite number (App::run adds it to every floating-point option).
extern const CLI::Validator Finite;

/// The camera an `--intrinsics fx,fy,cx,cy` option gives (the option declared with
/// expected(4)): none when the option was not given. Throws CLI::ValidationError naming
/// `option` unless fx, fy > 0 and every value is finite.
std::optional<PinholeCamera> intrinsics_option(const std::vector<double>& values, const char* option = "--intrinsics");

/// `text` fit for a terminal: newlines, control bytes and invalid UTF-8 escaped (\n, \xHH).
std::string printable(std::string_view text);

}  // namespace kestrel::cli
