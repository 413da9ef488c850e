// Acceptance of the message set on real data: kestrel-tum-play writes fr1_rpy to a log, the
// stock lcm-logplayer plays it, kestrel-monitor decodes every message. Skips without the data.

#include <gtest/gtest.h>

#include "test/monitor/logplayer_fixture.h"
#include "test/replay/fixtures.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

// The real sequence, through the real driver: data label.
TEST(LogPlayerMonitorData, TumSequenceThroughLcmLogplayer) {
  KESTREL_REQUIRE_TUM(sequence, "rgbd_dataset_freiburg1_rpy");
  if (!std::filesystem::exists(tool("tum-play")))
    KESTREL_SKIP_ENVIRONMENT() << tool("tum-play") << " is not built";
  KESTREL_REQUIRE_ISOLATION();
  TempDir dir;
  const RunResult made = run({tool("tum-play"), sequence.string(), "--log", (dir / "x.lcmlog").string()}, 300.0);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const auto want = count_events(dir / "x.lcmlog");
  ASSERT_EQ(want.at("CAMERA_RGBD"), 200);
  int64_t total = 0;
  for (const auto& [c, n] : want) total += n;
  const Monitored m = play_and_monitor(dir, dir / "x.lcmlog", total);
  EXPECT_EQ(m.exit_code, 0) << m.err;
  expect_counts(m.summary, want);
  EXPECT_EQ(m.summary["decode_failures"], 0);
}

}  // namespace
}  // namespace kestrel::test
