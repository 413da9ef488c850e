// kestrel-replay --speed / --realtime: pacing on the events' time stamps, like lcm-logplayer.
// Not a timing test: it checks that pacing happens at all and roughly at the asked rate.

#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>

#include "kestrel/imu_t.hpp"
#include "test/replay/fixtures.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

class TimedReplay : public ::testing::Test {
 protected:
  void SetUp() override { KESTREL_REQUIRE_ISOLATION(); }
  TempDir dir;
};

void write_imu_log(const std::filesystem::path& path, const std::vector<int64_t>& utimes) {
  transport::LogWriter w(path);
  for (size_t i = 0; i < utimes.size(); ++i) {
    kestrel::imu_t m{};
    m.utime = utimes[i];
    m.seq = static_cast<int64_t>(i);
    w.write_message("IMU", m.utime, m);
  }
  w.close();
}

TEST_F(TimedReplay, SpeedTenPlaysFiveSecondsInAboutHalfASecond) {
  TestLogSpec spec;
  spec.frames = 51;
  spec.width = 32;
  spec.height = 24;
  spec.frame_period_us = 100'000;  // 5.0 s of log
  spec.imu_per_frame = 1;
  spec.ground_truth = false;
  write_test_log(dir / "in.lcmlog", spec);
  LcmTap tap;
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "in.lcmlog").string(), "--speed", "10", "--json"});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mode"], "timed (speed 10)");
  EXPECT_EQ(j["events_replayed"], 102);
  EXPECT_NEAR(j["data_s"].get<double>(), 5.0005, 1e-6);
  EXPECT_GT(wall, 0.45);  // paced: not as fast as possible
  EXPECT_LT(wall, 3.0);   // but not at speed 1 either
  EXPECT_TRUE(tap.wait_until([&] { return tap.count("CAMERA_RGBD") == 51 && tap.count("IMU") == 51; }, 5.0))
      << tap.count("CAMERA_RGBD") << " frames and " << tap.count("IMU") << " IMU samples received";
}

TEST_F(TimedReplay, StartAndDurationCutTheLogInLogTime) {
  std::vector<int64_t> t;
  for (int i = 0; i <= 100; ++i) t.push_back(10'000'000 + i * 100'000);  // 10 Hz for 10 s
  write_imu_log(dir / "imu.lcmlog", t);
  const RunResult r = run({tool("replay"), (dir / "imu.lcmlog").string(), "--speed", "100",
                           "--start", "2", "--duration", "3", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["events_replayed"], 31);  // 2.0 s .. 5.0 s inclusive
  EXPECT_EQ(j["outside_window"], 70);
}

TEST_F(TimedReplay, EventsOutOfTimeOrderGoOutAtOnceAndAreCounted) {
  write_imu_log(dir / "jumbled.lcmlog", {0, 1'000'000, 500'000, 2'000'000, 100});
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "jumbled.lcmlog").string(), "--speed", "4", "--json"});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["events_replayed"], 5);
  EXPECT_EQ(j["out_of_order"], 2);
  EXPECT_LT(wall, 2.0);  // 2 s of log at speed 4; going back in time never waits
  EXPECT_GT(wall, 0.4);
}

}  // namespace
}  // namespace kestrel::test
