// The LiveSystem fixture itself (test/support/live_system.h): a process's pid comes from its
// heartbeat, a wait that times out fails the test naming what it waited for, and nothing a
// test started, nor anything its children left behind, outlives the fixture.

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <signal.h>

#include <cerrno>
#include <stdexcept>
#include <string>

#include "common/transport/channels.h"
#include "kestrel/process_status_t.hpp"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

bool alive(pid_t pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

TEST(LiveSystem, APidComesFromTheHeartbeatAndAStoppedProcessSaysHowItEnded) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  TempDir dir;
  LiveSystem live(dir.path(), {});
  const pid_t pid = live.start("estimator", {tool("estimator").string(), "-q"});
  EXPECT_EQ(live.wait_running("estimator"), pid);
  EXPECT_FALSE(live.wait_exit("estimator", 0.0).has_value());
  EXPECT_EQ(live.stop("estimator"), 0) << live.output("estimator");
  EXPECT_EQ(live.run("false", {"false"}, 10.0), 1);
  EXPECT_EQ(live.run("missing", {(dir / "no-such-program").string()}, 10.0), 127);
  EXPECT_NE(live.output("missing").find("no-such-program"), std::string::npos) << live.output("missing");
}

TEST(LiveSystem, AWaitThatTimesOutFailsNamingWhatItWaitedFor) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  TempDir dir;
  LiveSystem live(dir.path(), {{channel::kState}, {}, {}});
  std::optional<kestrel::process_status_t> got;
  EXPECT_NONFATAL_FAILURE(got = live.wait_for<kestrel::process_status_t>(
                              channel::kProcessStatus, [](const kestrel::process_status_t&) { return true; }, 0.2,
                              "a heartbeat nobody sends"),
                          "for a heartbeat nobody sends on PROCESS_STATUS");
  EXPECT_FALSE(got.has_value());
  live.start("sleeper", {"sleep", "600"});
  EXPECT_NONFATAL_FAILURE(live.exit_status("sleeper", 0.1), "sleeper");
}

TEST(LiveSystem, ARecordedChannelItDoesNotSubscribeToIsRefused) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  TempDir dir;
  try {
    LiveSystem live(dir.path(), {{channel::kGroundTruth}, dir / "flight.lcmlog", {channel::kGroundTruth, channel::kState}});
    FAIL() << "a log that would silently lack STATE was started";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("STATE"), std::string::npos) << e.what();
  }
}

TEST(LiveSystem, NothingStartedOutlivesIt) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  TempDir dir;
  pid_t child = 0, orphan = 0;
  {
    LiveSystem live(dir.path(), {});
    child = live.start("sleeper", {"sleep", "600"});
    // A grandchild in a session of its own, whose parent exits: an orphan out of its group.
    ASSERT_EQ(live.run("parent", {"sh", "-c", "setsid sleep 600 & echo $! > " + quoted((dir / "orphan").string())},
                       10.0),
              0);
    orphan = static_cast<pid_t>(std::stol(read_file(dir / "orphan")));
    ASSERT_TRUE(alive(child));
    ASSERT_TRUE(alive(orphan));
  }
  EXPECT_FALSE(alive(child));
  EXPECT_FALSE(alive(orphan));
}

}  // namespace
}  // namespace kestrel::test
