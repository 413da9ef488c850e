#pragma once
// Plays an LCM log with the stock lcm-logplayer while kestrel-monitor listens, and collects
// the monitor's JSON summary. The caller must already be in a private network namespace.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "test/support/test_support.h"

namespace kestrel::test {

struct Monitored {
  int exit_code = -1;
  nlohmann::json summary;
  std::string err;
};

/// Starts kestrel-monitor, waits until it listens, plays `log`, and waits until the monitor
/// has seen `expected` messages (60 s at most).
Monitored play_and_monitor(const TempDir& dir, const std::filesystem::path& log, int64_t expected);

/// Events per channel in a log, read independently of the monitor.
std::map<std::string, int64_t> count_events(const std::filesystem::path& log);

/// The summary's per-channel counts are exactly `want` (GoogleTest expectations).
void expect_counts(const nlohmann::json& summary, const std::map<std::string, int64_t>& want);

}  // namespace kestrel::test
