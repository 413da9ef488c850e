// The monitor's type table and traffic statistics on hand-made messages.

#include <gtest/gtest.h>

#include <filesystem>

#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/replay/fixtures.h"
#include "tools/monitor/traffic.h"

namespace kestrel::monitor {
namespace {

std::vector<uint8_t> imu_bytes(int64_t utime) {
  kestrel::imu_t m{};
  m.utime = utime;
  return transport::encode_message(m);
}

TEST(MessageTypes, KnowEveryKestrelTypeByNameAndFingerprint) {
  // One per file in lcmtypes/, counted there: a new type the table lacks fails here.
  size_t files = 0;
  for (const auto& f : std::filesystem::directory_iterator(test::source_dir() / "lcmtypes"))
    files += f.path().extension() == ".lcm";
  EXPECT_EQ(kestrel_types().size(), files);
  ASSERT_NE(find_type("imu_t"), nullptr);
  EXPECT_EQ(find_type("kestrel.imu_t"), find_type("imu_t"));
  EXPECT_EQ(find_type("nothing_t"), nullptr);
  const auto bytes = imu_bytes(1);
  EXPECT_EQ(identify(bytes.data(), bytes.size()), find_type("imu_t"));
  EXPECT_EQ(identify(bytes.data(), 7), nullptr);  // too short for a fingerprint
  const uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(identify(junk, 8), nullptr);
}

TEST(MessageTypes, DefaultTableCoversTheReadmeChannels) {
  const auto table = default_channel_types();
  EXPECT_EQ(table.at("CAMERA_RGBD"), find_type("rgbd_frame_t"));
  EXPECT_EQ(table.at("PROCESS_STATUS"), find_type("process_status_t"));
  EXPECT_EQ(table.at("PROCESS_REJECTIONS"), find_type("rejection_counts_t"));
  EXPECT_EQ(table.at("SLAM_SAVE_MAP"), find_type("map_save_request_t"));
  EXPECT_EQ(table.at("PLAYBACK_COMMAND"), find_type("playback_command_t"));
  EXPECT_EQ(table.at("PLAYBACK_STATUS"), find_type("playback_status_t"));
  EXPECT_EQ(table.at("PLAN_COVARIANCE"), find_type("plan_covariance_t"));
  EXPECT_EQ(table.at("SLAM_GRAPH_UNPLACED"), find_type("slam_graph_t"));
  EXPECT_EQ(table.size(), 20u);
  for (const auto& [channel, type] : table) EXPECT_NE(type, nullptr) << channel;
}

TEST(MessageTypes, ParsesChannelTypeSpecsAndNamesWhatIsWrong) {
  const auto [channel, type] = parse_channel_type("CAMERA_RGBD_Z=rgbd_frame_t");
  EXPECT_EQ(channel, "CAMERA_RGBD_Z");
  EXPECT_EQ(type, find_type("rgbd_frame_t"));
  for (const std::string bad : {"CAMERA", "=imu_t", "IMU=", "IMU=imu"}) {
    EXPECT_THROW(parse_channel_type(bad), std::invalid_argument) << bad;
  }
  try {
    parse_channel_type("IMU=imu");
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown message type 'imu'");
  }
}

TEST(TrafficMonitor, CountsAndChecksKnownChannels) {
  TrafficMonitor traffic(default_channel_types());
  const auto good = imu_bytes(5);
  EXPECT_EQ(traffic.on_message("IMU", good.data(), good.size(), 10.0), "");
  const auto wrong = transport::encode_message(kestrel::vo_update_t{});
  const std::string error = traffic.on_message("IMU", wrong.data(), wrong.size(), 10.5);
  EXPECT_EQ(error.rfind("IMU: ", 0), 0u) << error;
  EXPECT_NE(error.find("are not of type imu_t (another fingerprint"), std::string::npos) << error;
  auto truncated = good;
  truncated.resize(truncated.size() - 3);
  EXPECT_NE(traffic.on_message("IMU", truncated.data(), truncated.size(), 11.0), "");
  auto padded = good;
  padded.push_back(0);
  EXPECT_NE(traffic.on_message("IMU", padded.data(), padded.size(), 11.0).find("extra bytes"),
            std::string::npos);
  const ChannelStats& s = traffic.channels().at("IMU");
  EXPECT_EQ(s.count, 4);
  EXPECT_EQ(s.failures, 3);
  EXPECT_EQ(traffic.failures(), 3);
  EXPECT_EQ(s.bytes, static_cast<int64_t>(good.size() + wrong.size() + truncated.size() + padded.size()));
  EXPECT_TRUE(s.from_table);
}

TEST(TrafficMonitor, IdentifiesUnnamedChannelsByFingerprintAndChecksThem) {
  TrafficMonitor traffic(default_channel_types());
  const auto frame = transport::encode_message(transport::encode_rgbd(test::synthetic_frame(0, 16, 12)));
  EXPECT_EQ(traffic.on_message("CAMERA_RGBD_Z", frame.data(), frame.size(), 0.0), "");
  const ChannelStats& z = traffic.channels().at("CAMERA_RGBD_Z");
  EXPECT_EQ(z.type, find_type("rgbd_frame_t"));
  EXPECT_FALSE(z.from_table);
  // Once identified, another type on the channel is a failure.
  const auto imu = imu_bytes(1);
  EXPECT_NE(traffic.on_message("CAMERA_RGBD_Z", imu.data(), imu.size(), 0.1), "");
  EXPECT_EQ(z.failures, 1);

  const uint8_t raw[5] = {1, 2, 3, 4, 5};
  EXPECT_EQ(traffic.on_message("SOMETHING", raw, 5, 0.2), "");
  EXPECT_EQ(traffic.channels().at("SOMETHING").type, nullptr);
  EXPECT_EQ(traffic.failures(), 1);
}

TEST(TrafficMonitor, ReportsRatesPerWindowAndForTheWholeRun) {
  TrafficMonitor traffic(default_channel_types());
  const auto m = imu_bytes(1);
  for (int i = 0; i < 11; ++i) traffic.on_message("IMU", m.data(), m.size(), 100.0 + 0.1 * i);
  const std::string table = traffic.table(101.0);  // window 100.0 .. 101.0: 11 messages
  EXPECT_NE(table.find("IMU"), std::string::npos);
  EXPECT_NE(table.find("11.0"), std::string::npos) << table;
  EXPECT_EQ(traffic.channels().at("IMU").window_count, 0);
  const auto j = traffic.summary(2.0);
  EXPECT_EQ(j["messages"], 11);
  EXPECT_EQ(j["channels"]["IMU"]["type"], "imu_t");
  EXPECT_EQ(j["channels"]["IMU"]["type_from"], "table");
  EXPECT_NEAR(j["channels"]["IMU"]["rate_hz"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["channels"]["IMU"]["bandwidth_Bps"].get<double>(), 11.0 * m.size() / 2.0, 1e-9);
}

}  // namespace
}  // namespace kestrel::monitor
