#include "common/cli.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <iostream>

#include "common/error.h"

namespace kestrel::cli {

const CLI::Validator Positive(
    [](std::string& s) -> std::string {
      try {
        if (std::stod(s) > 0.0) return {};
      } catch (const std::exception&) {
      }
      return "must be a number greater than 0, got '" + s + "'";
    },
    "POSITIVE");

App::App(const std::string& name, const std::string& description)
    : CLI::App(description, "kestrel-" + name) {
  set_config("--config", "", "Read options from an INI file (keys are the long option names)");
  allow_config_extras(CLI::config_extras_mode::error);
  add_flag("--print-config", print_config_, "Print the effective configuration as INI and exit");
  add_flag(
      "-v,--verbose", [this](int64_t n) { verbosity_ += static_cast<int>(n); },
      "More log output (repeat for debug and trace)");
  add_flag(
      "-q,--quiet", [this](int64_t n) { verbosity_ -= static_cast<int>(n); },
      "Less log output (warnings and errors only; twice: errors only)");
  get_formatter()->column_width(34);
}

int App::run(int argc, char** argv, const std::function<int()>& body) {
  const std::string tool = get_name();
  try {
    parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return exit(e);
  } catch (const CLI::CallForVersion& e) {
    return exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << tool << ": error: " << e.what() << "\n"
              << "Run '" << tool << " --help' for usage.\n";
    return kExitUsage;
  }
  if (print_config_) {
    std::cout << config_to_str(true, true);
    return kExitOk;
  }

  auto logger = spdlog::stderr_color_mt(tool);
  logger->set_pattern("%n: %^%l%$: %v");
  const int level = std::clamp(static_cast<int>(spdlog::level::info) - verbosity_,
                               static_cast<int>(spdlog::level::trace),
                               static_cast<int>(spdlog::level::err));
  logger->set_level(static_cast<spdlog::level::level_enum>(level));
  spdlog::set_default_logger(logger);

  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const UnavailableError& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitUnavailable;
  } catch (const CLI::ParseError& e) {  // validation done inside the body
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return kExitFailure;
  }
}

}  // namespace kestrel::cli
