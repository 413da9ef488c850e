// kestrel-replay --speed / --realtime: pacing on the events' time stamps, like lcm-logplayer,
// and --max-gap, which keeps one event stamped an hour ahead from stalling the replay.
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

// How many times `needle` occurs in `text`.
size_t occurrences(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

constexpr int64_t kHour_us = 3'600'000'000;

TEST_F(TimedReplay, RealtimeCapsAGapOfAnHourAtFiveSecondsByDefault) {
  write_imu_log(dir / "ahead.lcmlog", {1'000'000, 1'000'000 + kHour_us});
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "ahead.lcmlog").string(), "--realtime", "--json"}, 60.0);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["events_replayed"], 2);
  EXPECT_EQ(j["gaps_capped"], 1);
  EXPECT_NEAR(j["gap_time_cut_s"].get<double>(), 3595.0, 1e-6);
  EXPECT_NEAR(j["data_s"].get<double>(), 3600.0, 1e-6);  // the stamps are the log's own
  EXPECT_GT(wall, 4.5);   // the capped gap is still waited for, 5 s of it
  EXPECT_LT(wall, 30.0);  // an hour without the cap
  EXPECT_NE(r.err.find("a gap of 3600.000 s before an event on IMU is played as 5 s"), std::string::npos) << r.err;
}

TEST_F(TimedReplay, EveryLongGapIsCappedAndSaidOnce) {
  // Two hour-long gaps, then ordinary 0.1 s steps; the cap is in log seconds, before --speed.
  write_imu_log(dir / "gaps.lcmlog", {0, kHour_us, 2 * kHour_us, 2 * kHour_us + 100'000, 2 * kHour_us + 200'000});
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "gaps.lcmlog").string(), "--speed", "2", "--max-gap", "1",
                           "--json"}, 60.0);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["events_replayed"], 5);
  EXPECT_EQ(j["gaps_capped"], 2);
  EXPECT_EQ(j["out_of_order"], 0);
  EXPECT_GT(wall, 1.0);   // (1 + 1 + 0.1 + 0.1) s of log at speed 2
  EXPECT_LT(wall, 10.0);
  EXPECT_EQ(occurrences(r.err, "is played as 1 s"), 1u) << r.err;  // said once, for the first gap
}

// One event stamped an hour ahead in the middle of a log: the gap to it is capped and the jump
// back from it restarts the pacing, so the events after it keep their 0.1 s steps instead of
// going out at once as "out of order".
TEST_F(TimedReplay, AnOutlierStampAheadCostsOneCappedGapAndThePacingResumesAfterIt) {
  std::vector<int64_t> t = {0, 100'000, kHour_us};
  for (int i = 2; i <= 11; ++i) t.push_back(i * 100'000);
  write_imu_log(dir / "outlier.lcmlog", t);
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "outlier.lcmlog").string(), "--speed", "2", "--max-gap", "0.5",
                           "--json"}, 60.0);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["events_replayed"], 13);
  EXPECT_EQ(j["gaps_capped"], 2);   // the gap to the outlier, the jump back from it
  EXPECT_EQ(j["out_of_order"], 0);  // none of the ten after it
  // (0.1 + 0.5 + 0.9) s of log at speed 2 (0.75 s): the steps after the outlier are still paced.
  EXPECT_GT(wall, 0.7);
}

TEST_F(TimedReplay, MaxGapZeroWaitsOutEveryGap) {
  write_imu_log(dir / "slow.lcmlog", {0, 8'000'000});  // 8 s apart: over the default 5 s cap
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run({tool("replay"), (dir / "slow.lcmlog").string(), "--speed", "8", "--max-gap", "0",
                           "--json"}, 60.0);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["gaps_capped"], 0);
  EXPECT_GT(wall, 0.9);  // the whole 1 s (8 s of log at speed 8); capped, it would be 0.625 s
  EXPECT_EQ(r.err.find("--max-gap"), std::string::npos) << r.err;
}

TEST_F(TimedReplay, MaxGapMustBeAFiniteNonNegativeNumber) {
  write_imu_log(dir / "one.lcmlog", {0});
  for (const char* bad : {"-1", "inf", "nan", "5s", "soon"}) {
    const RunResult r = run({tool("replay"), (dir / "one.lcmlog").string(), "--realtime", "--max-gap", bad});
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--max-gap"), std::string::npos) << bad << ": " << r.err;
  }
}

}  // namespace
}  // namespace kestrel::test
