// ProcessTable: what the replay learns from heartbeats.

#include <gtest/gtest.h>

#include "tools/replay/process_table.h"

namespace kestrel::replay {
namespace {

kestrel::process_status_t heartbeat(const std::string& name, int32_t pid,
                                    std::vector<std::string> subs, std::vector<std::string> pubs) {
  kestrel::process_status_t s{};
  s.name = name;
  s.pid = pid;
  s.subscriptions = std::move(subs);
  s.num_subscriptions = static_cast<int32_t>(s.subscriptions.size());
  s.publications = std::move(pubs);
  s.num_publications = static_cast<int32_t>(s.publications.size());
  return s;
}

TEST(ProcessTable, ReportsChangesOnlyWhenTheGraphChanges) {
  ProcessTable table;
  EXPECT_TRUE(table.update(heartbeat("vo", 10, {"CAMERA_RGBD"}, {"PROCESS_STATUS", "VO_UPDATE"}), 0.0));
  EXPECT_FALSE(table.update(heartbeat("vo", 10, {"CAMERA_RGBD"}, {"VO_UPDATE", "PROCESS_STATUS"}), 1.0));
  EXPECT_TRUE(table.update(heartbeat("vo", 10, {"CAMERA_RGBD"}, {"VO_UPDATE", "DEBUG"}), 2.0));
  EXPECT_TRUE(table.update(heartbeat("est", 11, {"IMU", "VO_UPDATE"}, {"STATE"}), 2.0));
  EXPECT_EQ(table.processes().at("vo").last_heard_s, 2.0);
}

TEST(ProcessTable, KnowsConsumersAndPublishersWithoutProtocolChannels) {
  ProcessTable table;
  table.update(heartbeat("vo", 1, {"CAMERA_RGBD"}, {"PROCESS_STATUS", "VO_UPDATE"}), 0.0);
  table.update(heartbeat("slam", 2, {"VO_UPDATE", "CAMERA_RGBD"}, {"SLAM_GRAPH"}), 0.0);
  table.update(heartbeat("est", 3, {"VO_UPDATE", "REPLAY_CONTROL"}, {"STATE"}), 0.0);
  const ConsumerMap consumers = table.consumers();
  EXPECT_EQ(consumers.at("CAMERA_RGBD"), (std::vector<std::string>{"slam", "vo"}));
  EXPECT_EQ(consumers.at("VO_UPDATE"), (std::vector<std::string>{"est", "slam"}));
  EXPECT_EQ(consumers.count("REPLAY_CONTROL"), 0u);
  EXPECT_EQ(table.publishers("VO_UPDATE"), std::vector<std::string>{"vo"});
  EXPECT_TRUE(table.publishers("PROCESS_STATUS").empty());
  EXPECT_TRUE(table.publishers("IMU").empty());
  EXPECT_EQ(describe(table)[2], "vo (pid 1): CAMERA_RGBD -> VO_UPDATE");
}

// Heartbeats and rejection counts are telemetry of the processes, not their output: a
// recording of a replay must not hold them (they carry the wall clock and, for the counts,
// what earlier runs refused, so two replays of one log would differ).
TEST(ProcessTable, TelemetryAndProtocolChannelsAreNotData) {
  for (const char* c :
       {"PROCESS_STATUS", "PROCESS_REJECTIONS", "REPLAY_CONTROL", "REPLAY_ACK", "PLAYBACK_COMMAND", "PLAYBACK_STATUS"})
    EXPECT_TRUE(is_protocol_channel(c)) << c;
  for (const char* c : {"STATE", "IMU", "PROCESS_STATUS_X"}) EXPECT_FALSE(is_protocol_channel(c)) << c;
}

TEST(ProcessTable, AProcessRemovedIsNoLongerAConsumerNorMissingFromOthers) {
  ProcessTable table;
  table.update(heartbeat("est", 3, {"IMU"}, {"STATE"}), 0.0);
  table.update(heartbeat("follow", 4, {"STATE"}, {"VEHICLE_COMMAND"}), 0.0);
  table.remove("est");
  EXPECT_FALSE(table.contains("est"));
  EXPECT_EQ(table.consumers().count("IMU"), 0u);
  EXPECT_EQ(table.consumers().at("STATE"), std::vector<std::string>{"follow"});
  table.remove("nobody");  // harmless
  EXPECT_EQ(table.processes().size(), 1u);
}

TEST(ProcessTable, NamesTheMissingExpectedProcesses) {
  ProcessTable table;
  table.update(heartbeat("a", 1, {}, {}), 0.0);
  EXPECT_EQ(table.missing({"a", "b", "c"}), (std::vector<std::string>{"b", "c"}));
  EXPECT_TRUE(table.missing({"a"}).empty());
  EXPECT_EQ(describe(table)[0], "a (pid 1): - -> -");
}

TEST(ProcessTable, FlagsTwoLiveProcessesSharingAName) {
  ProcessTable table(3.0);
  table.update(heartbeat("codec", 100, {"A"}, {"B"}), 0.0);
  EXPECT_TRUE(table.conflicts(0.5).empty());
  table.update(heartbeat("codec", 200, {"A"}, {"B"}), 1.0);
  EXPECT_EQ(table.conflicts(1.0), std::vector<std::string>{"codec (pids 100, 200)"});
  // A restart: the old pid falls silent and leaves the window.
  table.update(heartbeat("codec", 200, {"A"}, {"B"}), 5.0);
  EXPECT_TRUE(table.conflicts(5.0).empty());
}

}  // namespace
}  // namespace kestrel::replay
