// EventFilter: which log events a replay publishes, and the reasons it gives for the rest.

#include <gtest/gtest.h>

#include "common/error.h"
#include "tools/replay/event_filter.h"

namespace kestrel::replay {
namespace {

transport::LogEvent event(const std::string& channel, int64_t timestamp) {
  transport::LogEvent e;
  e.channel = channel;
  e.timestamp = timestamp;
  return e;
}

TEST(EventFilter, NeverReplaysTheProtocolChannels) {
  EventFilter filter({}, nullptr);
  EXPECT_TRUE(filter.accept(event("IMU", 0)));
  EXPECT_FALSE(filter.accept(event("PROCESS_STATUS", 1)));
  EXPECT_FALSE(filter.accept(event("REPLAY_ACK", 2)));
  EXPECT_FALSE(filter.accept(event("REPLAY_CONTROL", 3)));
  EXPECT_EQ(filter.skipped_channels().size(), 3u);
  EXPECT_EQ(filter.skipped_channels().at("REPLAY_ACK").events, 1);
}

TEST(EventFilter, SkipsWhatLiveProcessesPublishNamingThem) {
  auto publishers = [](const std::string& c) {
    return c == "VO_UPDATE" ? std::vector<std::string>{"vo", "vo2"} : std::vector<std::string>{};
  };
  EventFilter filter({}, publishers);
  EXPECT_TRUE(filter.accept(event("CAMERA_RGBD", 0)));
  EXPECT_FALSE(filter.accept(event("VO_UPDATE", 1)));
  EXPECT_FALSE(filter.accept(event("VO_UPDATE", 2)));
  const SkippedChannel& s = filter.skipped_channels().at("VO_UPDATE");
  EXPECT_EQ(s.events, 2);
  EXPECT_EQ(s.reason, "published by live process vo, vo2");
}

TEST(EventFilter, AnExplicitRegexSelectsWholeNamesAndOverridesTheLiveRule) {
  auto publishers = [](const std::string&) { return std::vector<std::string>{"someone"}; };
  EventFilter filter({"CAMERA_.*|IMU", 0.0, 0.0}, publishers);
  EXPECT_TRUE(filter.accept(event("CAMERA_RGBD", 0)));
  EXPECT_TRUE(filter.accept(event("IMU", 0)));
  EXPECT_FALSE(filter.accept(event("IMU_RAW", 0)));  // the whole name must match
  EXPECT_FALSE(filter.accept(event("GROUND_TRUTH", 0)));
  EXPECT_EQ(filter.skipped_channels().at("GROUND_TRUTH").reason, "not selected by --channels");
}

TEST(EventFilter, KeepsTheTimeWindowRelativeToTheFirstEvent) {
  EventFilter filter({"", 1.0, 2.0}, nullptr);
  const int64_t t0 = 5'000'000;
  EXPECT_FALSE(filter.accept(event("IMU", t0)));               // 0 s
  EXPECT_FALSE(filter.accept(event("IMU", t0 + 999'999)));     // just before 1 s
  EXPECT_TRUE(filter.accept(event("IMU", t0 + 1'000'000)));    // 1 s
  EXPECT_TRUE(filter.accept(event("IMU", t0 + 3'000'000)));    // 3 s: the end is included
  EXPECT_FALSE(filter.accept(event("IMU", t0 + 3'000'001)));
  EXPECT_EQ(filter.outside_window(), 3);
}

TEST(EventFilter, OneThatStartsMidLogCountsTheWindowFromTheLogsStartItIsGiven) {
  // A seek reads from a checkpoint in the middle of the log (seek_index.h): its first event
  // is not the log's.
  const int64_t t0 = 5'000'000;
  EventFilter filter({"", 1.0, 2.0}, nullptr, t0);
  EXPECT_TRUE(filter.accept(event("IMU", t0 + 2'500'000)));   // 2.5 s of the log's time
  EXPECT_TRUE(filter.accept(event("IMU", t0 + 3'000'000)));
  EXPECT_FALSE(filter.accept(event("IMU", t0 + 3'000'001)));  // beyond 1 + 2 s
  EXPECT_EQ(filter.outside_window(), 1);
}

TEST(EventFilter, WithoutAWindowNothingIsOutsideIt) {
  EventFilter filter({}, nullptr);  // neither --start nor --duration
  const int64_t t0 = 5'000'000;
  EXPECT_TRUE(filter.accept(event("IMU", t0)));
  EXPECT_TRUE(filter.accept(event("IMU", t0 - 3'600'000'000)));  // an hour before the first event
  EXPECT_TRUE(filter.accept(event("IMU", t0 + 3'600'000'000)));
  EXPECT_EQ(filter.outside_window(), 0);
  EventFilter started({"", 1.0, 0.0}, nullptr);  // --start 1: earlier events are left out
  EXPECT_FALSE(started.accept(event("IMU", t0)));
  EXPECT_FALSE(started.accept(event("IMU", t0 - 1)));
  EXPECT_TRUE(started.accept(event("IMU", t0 + 1'000'000)));
  EXPECT_EQ(started.outside_window(), 2);
}

TEST(EventFilter, ChecksRegexes) {
  EXPECT_EQ(check_channel_regex("CAMERA_.*"), "");
  EXPECT_NE(check_channel_regex("CAMERA_(").find("not a valid regular expression"), std::string::npos);
}

}  // namespace
}  // namespace kestrel::replay
