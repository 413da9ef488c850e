#pragma once
// The INI form of a tool's configuration: what --print-config writes and --config reads, made
// so that a printed configuration read back gives the same configuration and prints the same.
//
// * A line is `key = value`, `key = [v1, v2, ...]` (a list may run over several lines), a bare
//   `key` (a flag set to true), a comment (first non-blank character '#' or ';') or blank. A
//   value is bare (it ends at a comma, a blank or, in a list, ']') or quoted: "..." with the
//   escapes \\ \" \n \t \r \xHH, or '...' taken literally. A '#' that follows a blank outside
//   quotes starts a comment. Values separated by commas or blanks are a list (CLI11's own
//   files write `key=1,2,3`), so a string with either is written quoted.
// * Reading checks every key against the app before CLI11 sees it: an unknown key, one a file
//   cannot set (help, config, print-config), a key given twice or a malformed line is a
//   ConfigLineError naming the line. There are no sections: no kestrel tool has subcommands.
// * Writing puts down only the options that were set (on the command line or in a file), each
//   as it was typed: CLI11's transforms turn a name into a number ("ekf" -> 0) and CLI11's own
//   default strings round doubles to six digits, so neither is ever written as a value. Every
//   other option is shown as a comment with its default (a value the option takes, so that the
//   line can be uncommented) and stays at its default when the file is read: the defaults of
//   the build that reads the file, not of the one that wrote it.

#include <CLI/CLI.hpp>

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace kestrel::cli {

/// The values each option was given, as typed (before any transform), in order.
using GivenValues = std::map<const CLI::Option*, std::vector<std::string>>;

/// A malformed or unusable line of a configuration file; App::run names the file.
class ConfigLineError : public CLI::ConfigError {
 public:
  ConfigLineError(int line, const std::string& reason);
  int line() const { return line_; }
  const std::string& reason() const { return reason_; }

 private:
  int line_;
  std::string reason_;
};

/// `value` as one INI value: bare if it is a number or true/false, else double-quoted with
/// escapes (non-printing bytes and invalid UTF-8 as \xHH).
std::string ini_value(const std::string& value);

/// The values of `option`'s default string: CLI11 shows a vector as "[1,2]", tools write
/// "1,2" for an option that takes several values; none for an empty default.
std::vector<std::string> default_values(const CLI::Option& option);

/// Reads and writes the format above for one app. Both pointers must outlive the formatter;
/// `given` may be null (then the options' results are written, as CLI11 holds them).
class IniConfig : public CLI::Config {
 public:
  IniConfig(const CLI::App* app, const GivenValues* given) : app_(app), given_(given) {}

  std::vector<CLI::ConfigItem> from_config(std::istream& input) const override;
  /// The configuration of `app` (CLI11's other arguments are ignored: the form is fixed).
  std::string to_config(const CLI::App* app, bool, bool, std::string) const override;

 private:
  const CLI::App* app_;
  const GivenValues* given_;
};

}  // namespace kestrel::cli
