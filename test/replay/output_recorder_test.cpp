// OutputRecorder: the canonical order that makes recordings comparable byte for byte.

#include <gtest/gtest.h>

#include <algorithm>

#include "test/replay/fixtures.h"
#include "test/support/test_support.h"
#include "tools/replay/output_recorder.h"

namespace kestrel::replay {
namespace {

kestrel::process_status_t heartbeat(const std::string& name, std::vector<std::string> subs,
                                    std::vector<std::string> pubs) {
  kestrel::process_status_t s{};
  s.name = name;
  s.subscriptions = std::move(subs);
  s.publications = std::move(pubs);
  return s;
}

// CAMERA_RGBD -> vo -> VO_UPDATE -> est -> STATE -> planner -> PLAN;
// VO_UPDATE -> slam -> SLAM_CORRECTION -> est (a cycle); CAMERA_RGBD -> slam too.
ProcessTable system() {
  ProcessTable t;
  t.update(heartbeat("vo", {"CAMERA_RGBD"}, {"VO_UPDATE"}), 0);
  t.update(heartbeat("est", {"VO_UPDATE", "SLAM_CORRECTION", "IMU"}, {"STATE"}), 0);
  t.update(heartbeat("slam", {"VO_UPDATE", "CAMERA_RGBD"}, {"SLAM_CORRECTION", "SLAM_GRAPH"}), 0);
  t.update(heartbeat("planner", {"STATE"}, {"PLAN"}), 0);
  return t;
}

TEST(ChannelDepths, AreShortestDistancesThroughTheProcesses) {
  const auto d = channel_depths("CAMERA_RGBD", system());
  EXPECT_EQ(d.at("CAMERA_RGBD"), 0);
  EXPECT_EQ(d.at("VO_UPDATE"), 1);
  EXPECT_EQ(d.at("SLAM_CORRECTION"), 1);  // slam also reads the camera directly
  EXPECT_EQ(d.at("SLAM_GRAPH"), 1);
  EXPECT_EQ(d.at("STATE"), 2);
  EXPECT_EQ(d.at("PLAN"), 3);
  EXPECT_EQ(d.count("IMU"), 0u);
  const auto from_imu = channel_depths("IMU", system());
  EXPECT_EQ(from_imu.at("STATE"), 1);
  EXPECT_EQ(from_imu.count("VO_UPDATE"), 0u);
}

std::vector<uint8_t> bytes(const std::string& s) { return {s.begin(), s.end()}; }

// Records the same outputs arriving in a different order each time.
std::vector<uint8_t> record(const std::filesystem::path& path,
                            const std::vector<std::pair<std::string, std::string>>& arrivals) {
  OutputRecorder recorder(path);
  const auto depths = channel_depths("CAMERA_RGBD", system());
  for (const auto& [channel, payload] : arrivals) {
    const auto b = bytes(payload);
    recorder.add(channel, b.data(), b.size());
  }
  recorder.flush_event(42, depths);
  recorder.close();
  return test::read_bytes(path);
}

TEST(OutputRecorder, OrderDoesNotDependOnArrivalAcrossChannels) {
  test::TempDir dir;
  // Same per-channel order (STATE s1 before s2), different interleaving across channels.
  const auto a = record(dir / "a.lcmlog", {{"VO_UPDATE", "v"}, {"SLAM_GRAPH", "g"}, {"STATE", "s1"},
                                           {"STATE", "s2"}, {"DEBUG", "x"}, {"SLAM_CORRECTION", "c"}});
  const auto b = record(dir / "b.lcmlog", {{"DEBUG", "x"}, {"STATE", "s1"}, {"SLAM_CORRECTION", "c"},
                                           {"STATE", "s2"}, {"SLAM_GRAPH", "g"}, {"VO_UPDATE", "v"}});
  EXPECT_EQ(a, b);
  const auto events = test::read_log(dir / "a.lcmlog");
  std::vector<std::string> order;
  for (const auto& e : events) {
    order.push_back(e.channel + "=" + std::string(e.data.begin(), e.data.end()));
    EXPECT_EQ(e.timestamp, 42);
  }
  EXPECT_EQ(order, (std::vector<std::string>{"SLAM_CORRECTION=c", "SLAM_GRAPH=g", "VO_UPDATE=v",
                                             "STATE=s1", "STATE=s2", "DEBUG=x"}));
}

TEST(OutputRecorder, CountsPerChannelAcrossEvents) {
  test::TempDir dir;
  OutputRecorder recorder((dir / "r.lcmlog").string());
  const auto v = bytes("v");
  recorder.add("VO_UPDATE", v.data(), v.size());
  recorder.flush_event(1, {});
  recorder.flush_event(2, {});  // an event without outputs writes nothing
  recorder.add("VO_UPDATE", v.data(), v.size());
  recorder.add("STATE", v.data(), v.size());
  recorder.flush_event(3, {});
  recorder.close();
  EXPECT_EQ(recorder.recorded().at("VO_UPDATE"), 2);
  EXPECT_EQ(recorder.total(), 3);
  const auto events = test::read_log(dir / "r.lcmlog");
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[2].timestamp, 3);
  EXPECT_EQ(events[2].event_number, 2);
}

TEST(OutputRecorder, UnwritableFileIsAnInputError) {
  EXPECT_THROW(OutputRecorder("/nonexistent-dir/out.lcmlog"), InputError);
}

}  // namespace
}  // namespace kestrel::replay
