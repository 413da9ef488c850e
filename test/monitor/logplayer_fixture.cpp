#include "test/monitor/logplayer_fixture.h"

#include <gtest/gtest.h>

#include "common/transport/lcm_url.h"
#include "test/replay/fixtures.h"

namespace kestrel::test {

Monitored play_and_monitor(const TempDir& dir, const std::filesystem::path& log, int64_t expected) {
  Background monitor({tool("monitor"), "--json", "--period", "0", "--count", std::to_string(expected),
                      "--duration", "60"},
                     dir.path(), "monitor");
  Monitored m;
  if (!monitor.wait_for_output("listening", 10.0, /*in_stderr=*/true)) {
    ADD_FAILURE() << "kestrel-monitor did not start: " << monitor.err();
    return m;
  }
  const RunResult player = run({"lcm-logplayer", "-l", transport::kDefaultLcmUrl, log.string()}, 300.0);
  EXPECT_EQ(player.exit_code, 0) << "lcm-logplayer: " << player.err;
  m.exit_code = monitor.wait_exit(70.0).value_or(-1);
  m.err = monitor.err();
  try {
    m.summary = nlohmann::json::parse(monitor.out());
  } catch (const std::exception&) {
    ADD_FAILURE() << "no JSON summary; stdout: " << monitor.out() << "\nstderr: " << m.err;
  }
  return m;
}

std::map<std::string, int64_t> count_events(const std::filesystem::path& log) {
  std::map<std::string, int64_t> counts;
  for (const auto& e : read_log(log)) ++counts[e.channel];
  return counts;
}

void expect_counts(const nlohmann::json& summary, const std::map<std::string, int64_t>& want) {
  ASSERT_TRUE(summary.contains("channels")) << summary.dump();
  EXPECT_EQ(summary["channels"].size(), want.size());
  for (const auto& [channel, n] : want) {
    ASSERT_TRUE(summary["channels"].contains(channel)) << channel;
    EXPECT_EQ(summary["channels"][channel]["count"], n) << channel;
  }
}

}  // namespace kestrel::test
