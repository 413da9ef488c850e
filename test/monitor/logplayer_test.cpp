// The message set against the stock LCM tools: lcm-logplayer (Debian's liblcm-bin, knowing
// nothing of kestrel) plays a log while kestrel-monitor, built from the generated types,
// receives and decodes every message; and a --channels regex LCM cannot compile is a usage
// error, not a crash. Inside a private network namespace.

#include <gtest/gtest.h>

#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/monitor/logplayer_fixture.h"
#include "test/replay/fixtures.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

class LogPlayerMonitor : public ::testing::Test {
 protected:
  void SetUp() override { KESTREL_REQUIRE_ISOLATION(); }
  TempDir dir;
};

TEST_F(LogPlayerMonitor, EveryMessageOfAKestrelLogArrivesAndDecodes) {
  TestLogSpec spec;
  spec.frames = 60;
  spec.width = 320;
  spec.height = 240;
  const auto want = write_test_log(dir / "x.lcmlog", spec);
  int64_t total = 0;
  for (const auto& [c, n] : want) total += n;
  const Monitored m = play_and_monitor(dir, dir / "x.lcmlog", total);
  EXPECT_EQ(m.exit_code, 0) << m.err;
  expect_counts(m.summary, want);
  EXPECT_EQ(m.summary["decode_failures"], 0);
  EXPECT_EQ(m.summary["channels"]["CAMERA_RGBD"]["type"], "rgbd_frame_t");
}

TEST_F(LogPlayerMonitor, WrongTypeAndTruncatedMessagesAreCountedAndNamed) {
  {
    transport::LogWriter w(dir / "bad.lcmlog");
    kestrel::imu_t imu{};
    w.write_message("IMU", 1, imu);
    w.write_message("IMU", 2, kestrel::vo_update_t{});  // wrong type on a known channel
    auto frame = transport::encode_message(transport::encode_rgbd(synthetic_frame(0)));
    w.write("CAMERA_RGBD", 3, frame);
    frame.resize(frame.size() / 2);  // truncated
    w.write("CAMERA_RGBD", 4, frame);
    w.write("UNKNOWN_BYTES", 5, {1, 2, 3});
    w.close();
  }
  const Monitored m = play_and_monitor(dir, dir / "bad.lcmlog", 5);
  EXPECT_EQ(m.exit_code, 3);
  EXPECT_EQ(m.summary["decode_failures"], 2);
  EXPECT_EQ(m.summary["channels"]["IMU"]["decode_failures"], 1);
  EXPECT_EQ(m.summary["channels"]["CAMERA_RGBD"]["decode_failures"], 1);
  EXPECT_EQ(m.summary["channels"]["UNKNOWN_BYTES"]["type"], "raw");
  EXPECT_NE(m.err.find("IMU: "), std::string::npos) << m.err;
  EXPECT_NE(m.err.find("CAMERA_RGBD: "), std::string::npos) << m.err;
  EXPECT_NE(m.err.find("do not decode as their channel's type: CAMERA_RGBD (1), IMU (1)"),
            std::string::npos) << m.err;
}

TEST_F(LogPlayerMonitor, ARegexLcmCannotUseIsAUsageError) {
  const RunResult r = run({tool("monitor").string(), "--channels", "CAMERA_[", "--duration", "0.1"}, 20.0);
  EXPECT_EQ(r.exit_code, 2) << r.err;  // it was a crash (SIGSEGV)
  EXPECT_NE(r.err.find("kestrel-monitor: error: --channels: 'CAMERA_[' is not a regular expression"),
            std::string::npos) << r.err;
}

}  // namespace
}  // namespace kestrel::test
