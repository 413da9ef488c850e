#include "common/cli.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>

#include "common/error.h"
#include "common/text.h"

namespace kestrel::cli {
namespace {

// The whole of `s` as a double, as CLI11 converts it (strtod: "inf", "nan", "1e999" -> inf).
std::optional<double> as_number(const std::string& s) {
  if (s.empty() || std::isspace(static_cast<unsigned char>(s.front()))) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return std::nullopt;
  return v;
}

// "must be a number in [lo, hi]" from a CLI11 Range's description ("FLOAT in [0 - 1e+09]",
// "INT in [1 - 16]", NONNEGATIVE, POSITIVE) or, failing that, from its message ("Value x not in
// range 0.000000 to 1797...", whose std::to_string bounds are unreadable and lose small ones).
std::string range_message(const std::string& description, const std::string& message, const std::string& value) {
  const std::string got = ", got '" + value + "'";
  if (description == "NONNEGATIVE") return "must be a number >= 0" + got;
  if (description == "POSITIVE") return "must be a number > 0" + got;
  std::string what = description.rfind("INT", 0) == 0 || description.rfind("UINT", 0) == 0 ? "an integer" : "a number";
  std::optional<double> lo, hi;
  const size_t open = description.find(" in [");
  if (open != std::string::npos && description.back() == ']') {
    const std::string inner = description.substr(open + 5, description.size() - open - 6);
    const size_t dash = inner.find(" - ", 1);
    if (dash != std::string::npos) {
      lo = as_number(inner.substr(0, dash));
      hi = as_number(inner.substr(dash + 3));
    }
  }
  if (!lo || !hi) {
    const size_t in = message.find(" not in range "), to = message.rfind(" to ");
    if (in == std::string::npos || to == std::string::npos || to < in) return message;
    lo = as_number(message.substr(in + 14, to - in - 14));
    hi = as_number(message.substr(to + 4));
    what = "a number";
    if (!lo || !hi) return message;
  }
  if (*hi >= 1e300) return "must be " + what + " >= " + number_text(*lo) + got;
  if (*lo <= -1e300) return "must be " + what + " <= " + number_text(*hi) + got;
  return "must be " + what + " in [" + number_text(*lo) + ", " + number_text(*hi) + "]" + got;
}

// Wraps each of the option's validators so that a CLI11 range error reads as range_message().
void readable_range_errors(CLI::Option& option) {
  for (int i = 0;; ++i) {
    CLI::Validator* v = nullptr;
    try {
      v = option.get_validator(i);
    } catch (const CLI::OptionNotFound&) {
      return;
    }
    const CLI::Validator original = *v;
    const std::string description = v->get_description();
    v->operation([original, description](std::string& value) {
      std::string why = original(value);
      if (why.rfind("Value ", 0) == 0 && why.find(" not in range ") != std::string::npos)
        why = range_message(description, why, value);
      return why;
    });
  }
}

// Whether the option's own validators take its default: a tool may declare a value that means
// "not set" (an empty choice, 0 for a positive length), which is then not shown as a default,
// as it could not be given back.
bool takes_its_default(CLI::Option& option) {
  const std::vector<std::string> values = default_values(option);
  for (size_t k = 0; k < values.size(); ++k) {
    std::string value = values[k];
    for (int i = 0;; ++i) {
      const CLI::Validator* v = nullptr;
      try {
        v = option.get_validator(i);
      } catch (const CLI::OptionNotFound&) {
        break;
      }
      const int index = v->get_application_index();
      if ((index == -1 || index == static_cast<int>(k)) && !(*v)(value).empty()) return false;
    }
  }
  return true;
}

}  // namespace

const CLI::Validator Positive(
    [](std::string& s) -> std::string {
      const std::optional<double> v = as_number(s);
      if (v && std::isfinite(*v) && *v > 0.0) return {};
      return "must be a number greater than 0, got '" + s + "'";
    },
    "POSITIVE");

const CLI::Validator Finite(
    [](std::string& s) -> std::string {
      const std::optional<double> v = as_number(s);
      if (v && !std::isfinite(*v)) return "must be a finite number, got '" + s + "'";
      return {};  // not a number at all: the conversion says so, naming the option
    },
    "");

std::string printable(std::string_view text) { return escape_bytes(text); }

App::App(const std::string& name, const std::string& description)
    : CLI::App(description, "kestrel-" + name) {
  set_config("--config", "", "Read options from an INI file (keys are the long option names)");
  config_formatter(std::make_shared<IniConfig>(this, &given_));
  allow_config_extras(CLI::config_extras_mode::error);
  add_flag("--print-config", print_config_,
           "Print the options set as INI (the others as comments with their defaults) and exit")
      ->configurable(false);
  add_flag(
      "-v,--verbose", [this](int64_t n) { verbosity_ += static_cast<int>(n); },
      "More log output (repeat for debug and trace)");
  add_flag(
      "-q,--quiet", [this](int64_t n) { verbosity_ -= static_cast<int>(n); },
      "Less log output (warnings and errors only; twice: errors only)");
  get_formatter()->column_width(34);
}

void App::prepare_options() {
  for (CLI::Option* o : get_options()) {
    if (!o->get_configurable() || o == get_config_ptr() || o->get_expected_max() == 0) continue;
    if (o->get_default_str().empty()) o->capture_default_str();  // the value as declared
    if (o->get_default_str() == "[]") o->default_str("");      // an empty list: nothing to show
    readable_range_errors(*o);
    if (o->get_type_name().find("FLOAT") != std::string::npos) o->check(Finite);
    if (!takes_its_default(*o)) o->default_str("");
    // A transform runs before every other validator: it sees the value exactly as typed.
    o->transform(CLI::Validator(
        [this, o](std::string& value) {
          given_[o].push_back(value);
          return std::string();
        },
        ""));
  }
}

std::string App::config_source() const {
  const CLI::Option* config = get_config_ptr();
  if (config == nullptr || config->results().size() != 1) return "--config";
  return config->results().front();
}

int App::run(int argc, char** argv, const std::function<int()>& body) {
  const std::string tool = get_name();
  auto fail = [&](const std::string& what) { std::cerr << tool << ": error: " << printable(what) << "\n"; };
  prepare_options();
  try {
    parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return exit(e);
  } catch (const CLI::CallForVersion& e) {
    return exit(e);
  } catch (const ConfigLineError& e) {
    fail(at_line(config_source(), e.line(), e.reason()));
    return kExitUsage;
  } catch (const CLI::ParseError& e) {
    fail(e.what());
    std::cerr << "Run '" << tool << " --help' for usage.\n";
    return kExitUsage;
  }
  // A tool that passes what follows its options on (kestrel-isolated CMD...) takes an unknown
  // option for the start of that command: "-x" is a mistyped option, a command goes after "--".
  if (get_prefix_command() && !remaining().empty()) {
    const std::string first = remaining().front();
    if (first.size() > 1 && first[0] == '-' && first != "--") {
      fail("unknown option '" + first + "' (a command whose name starts with '-' goes after --)");
      std::cerr << "Run '" << tool << " --help' for usage.\n";
      return kExitUsage;
    }
  }
  if (print_config_) {
    std::cout << config_to_str();
    return kExitOk;
  }

  spdlog::drop(tool);  // a second App of the same name (tests) replaces the first's logger
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
    fail(e.what());
    return kExitBadInput;
  } catch (const UnavailableError& e) {
    fail(e.what());
    return kExitUnavailable;
  } catch (const CLI::ParseError& e) {  // validation done inside the body
    fail(e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    fail(e.what());
    return kExitFailure;
  }
}

std::optional<PinholeCamera> intrinsics_option(const std::vector<double>& values, const char* option) {
  if (values.empty()) return std::nullopt;
  if (values.size() != 4) throw CLI::ValidationError(option, "needs four values: fx,fy,cx,cy");
  PinholeCamera c;
  c.fx = values[0];
  c.fy = values[1];
  c.cx = values[2];
  c.cy = values[3];
  if (!(c.fx > 0 && c.fy > 0 && std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) && std::isfinite(c.cy)))
    throw CLI::ValidationError(option, "fx and fy must be > 0 and all values finite");
  return c;
}

}  // namespace kestrel::cli
