// The replay report as text and JSON.

#include <gtest/gtest.h>

#include "tools/replay/report.h"

namespace kestrel::replay {
namespace {

ReplayReport sample() {
  ReplayReport r;
  r.log_path = "x.lcmlog";
  r.mode = "lock-step";
  r.processes = {"codec (pid 7): CAMERA_RGBD -> CAMERA_RGBD_Z"};
  r.events_replayed = 12;
  r.replayed = {{"CAMERA_RGBD", 4}, {"IMU", 8}};
  r.skipped = {{"PROCESS_STATUS", {3, "heartbeats and replay protocol are never replayed"}}};
  r.damage = "x.lcmlog: damaged LCM log: truncated last event, 10 bytes skipped (first at byte 99)";
  r.data_s = 2.0;
  r.wall_s = 0.5;
  r.record_path = "out.lcmlog";
  r.recorded = {{"CAMERA_RGBD_Z", 4}};
  r.latency = {{"CAMERA_RGBD", "codec", "CAMERA_RGBD", 4, 1.5, 2.5, 3.0}};
  return r;
}

TEST(ReplayReport, TextNamesEveryCount) {
  const std::string text = format_text(sample());
  EXPECT_NE(text.find("lock-step replay of x.lcmlog"), std::string::npos) << text;
  EXPECT_NE(text.find("replayed 12 events: 2.000 s of log time in 0.500 s wall (4.0x)"), std::string::npos) << text;
  EXPECT_NE(text.find("PROCESS_STATUS"), std::string::npos);
  EXPECT_NE(text.find("truncated last event"), std::string::npos);
  EXPECT_NE(text.find("recorded 4 messages to out.lcmlog"), std::string::npos);
  EXPECT_NE(text.find("CAMERA_RGBD      codec        CAMERA_RGBD            4      1.50      2.50      3.00"),
            std::string::npos) << text;
}

TEST(ReplayReport, JsonCarriesTheSameFigures) {
  const nlohmann::json j = to_json(sample());
  EXPECT_EQ(j["events_replayed"], 12);
  EXPECT_EQ(j["replayed"]["IMU"], 8);
  EXPECT_EQ(j["skipped"]["PROCESS_STATUS"]["events"], 3);
  EXPECT_DOUBLE_EQ(j["speedup"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(j["latency"][0]["p95_ms"].get<double>(), 2.5);
  EXPECT_EQ(j["record"]["messages"], 4);
  EXPECT_EQ(j["record"]["channels"]["CAMERA_RGBD_Z"], 4);
  EXPECT_FALSE(j["interrupted"].get<bool>());
  ReplayReport empty;
  EXPECT_TRUE(to_json(empty)["replayed"].is_object());
  EXPECT_FALSE(to_json(empty).contains("record"));
}

TEST(ReplayReport, CappedGapsAreReportedOnlyWhenThereAreSome) {
  ReplayReport r = sample();
  EXPECT_EQ(format_text(r).find("--max-gap"), std::string::npos);
  r.gaps_capped = 2;
  r.gap_time_cut_s = 7190.0;
  EXPECT_NE(format_text(r).find("gaps over --max-gap: 2, 7190.000 s of log time not waited for"), std::string::npos)
      << format_text(r);
  EXPECT_EQ(to_json(r)["gaps_capped"], 2);
  EXPECT_DOUBLE_EQ(to_json(r)["gap_time_cut_s"].get<double>(), 7190.0);
}

}  // namespace
}  // namespace kestrel::replay
