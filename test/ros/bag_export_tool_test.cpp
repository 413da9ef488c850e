// kestrel-bag-export as a user runs it: a log gives a bag librosbag reads and a summary; a
// missing, truncated or STATE-less log is one error line, exit 3, and no bag, not even a
// temporary; bad options exit 2; the printed configuration reads back the same.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "test/ros/bag_export_logs.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

class BagExportTool : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::tool("bag-export"))) {
      KESTREL_SKIP_ENVIRONMENT() << test::tool("bag-export") << " is not built (the ROS packages are missing)";
    }
  }
  test::RunResult run(const fs::path& log, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {test::tool("bag-export").string(), log.string(), "--bag", bag().string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return test::run(argv, 60.0);
  }
  fs::path bag() const { return dir_ / "out.bag"; }
  void expect_refused(const fs::path& log, const std::string& words) {
    const test::RunResult r = run(log);
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_EQ(r.err.rfind("kestrel-bag-export: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(bag())) << "a failed export left " << bag();
    for (const auto& e : fs::directory_iterator(dir_.path()))
      EXPECT_EQ(e.path().filename().string().find(".out.bag.tmp"), std::string::npos) << "temporary left: " << e.path();
  }
  test::TempDir dir_;
};

TEST_F(BagExportTool, ALogGivesABagAndASummary) {
  const auto states = test::write_state_log(dir_ / "in.lcmlog", 30, true);
  const test::RunResult r = run(dir_ / "in.lcmlog");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("/kestrel/odom: 30 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/tf: 30 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/tf_static: 1 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("messages written: 61\n"), std::string::npos) << r.out;
  rosbag::Bag b(bag().string(), rosbag::bagmode::Read);
  size_t i = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(b, rosbag::TopicQuery("/kestrel/odom"))) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(o);
    ASSERT_LT(i, states.size());
    EXPECT_NEAR(o->pose.pose.position.x, states[i].T_world_body.position[0], 1e-9);
    EXPECT_NEAR(o->pose.pose.orientation.w, states[i].T_world_body.orientation[0], 1e-9);
    ++i;
  }
  EXPECT_EQ(i, states.size());
}

// The bag read by ROS's own Python reader (python3-rosbag, Debian's /usr/bin/python3): every
// STATE is an Odometry there with the same stamp and pose.
TEST_F(BagExportTool, PythonRosbagReadsTheSameOdometry) {
  const char* python = "/usr/bin/python3";
  if (test::run({python, "-c", "import rosbag"}, 30.0).exit_code != 0)
    KESTREL_SKIP_ENVIRONMENT() << "python3-rosbag is not installed";
  const auto states = test::write_state_log(dir_ / "in.lcmlog", 30, true);
  ASSERT_EQ(run(dir_ / "in.lcmlog").exit_code, 0);
  const test::RunResult r = test::run(
      {python, "-c",
       "import sys, rosbag\n"
       "for _, m, t in rosbag.Bag(sys.argv[1]).read_messages(topics=['/kestrel/odom']):\n"
       "    p = m.pose.pose\n"
       "    print(m.header.stamp.to_nsec() // 1000, m.header.frame_id, m.child_frame_id, '%.17g %.17g %.17g %.17g %.17g %.17g %.17g' %"
       " (p.position.x, p.position.y, p.position.z, p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z))\n",
       bag().string()},
      60.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(r.out);
  size_t i = 0;
  int64_t utime = 0;
  std::string parent, child;
  double v[7];
  while (in >> utime >> parent >> child >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5] >> v[6]) {
    ASSERT_LT(i, states.size());
    const kestrel::state_t& s = states[i++];
    EXPECT_EQ(utime, s.utime);
    EXPECT_EQ(parent, "map");
    EXPECT_EQ(child, "base_link");
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(v[k], s.T_world_body.position[k], 1e-9);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(v[3 + k], s.T_world_body.orientation[k], 1e-9);
  }
  EXPECT_EQ(i, states.size()) << r.out;
}

TEST_F(BagExportTool, MissingLog) { expect_refused(dir_ / "absent.lcmlog", "absent.lcmlog"); }

TEST_F(BagExportTool, TruncatedLog) {
  test::write_state_log(dir_ / "whole.lcmlog", 30, true);
  const std::string bytes = test::read_file(dir_ / "whole.lcmlog");
  std::ofstream(dir_ / "cut.lcmlog", std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  expect_refused(dir_ / "cut.lcmlog", "damaged LCM log: truncated last event");
}

TEST_F(BagExportTool, NotALog) {
  std::ofstream(dir_ / "text.lcmlog") << "not a log at all\n";
  const test::RunResult r = run(dir_ / "text.lcmlog");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_FALSE(fs::exists(bag()));
}

TEST_F(BagExportTool, LogWithoutState) {
  {
    transport::LogWriter w((dir_ / "other.lcmlog").string());
    w.write(channel::kImu, 1000000, std::vector<uint8_t>(8, 0));
    w.close();
  }
  expect_refused(dir_ / "other.lcmlog", "none of the channels exported");
}

// Images are exported only when asked: a log of camera frames alone is refused without
// --images, and exported with it.
TEST_F(BagExportTool, CameraFramesOnlyWithImages) {
  {
    transport::LogWriter w((dir_ / "camera.lcmlog").string());
    transport::LogReader r([&] {
      test::write_state_log(dir_ / "all.lcmlog", 9, true);
      return (dir_ / "all.lcmlog").string();
    }());
    while (auto e = r.next())
      if (e->channel == channel::kCameraRgbd) w.write(e->channel, e->timestamp, e->data);
    w.close();
  }
  expect_refused(dir_ / "camera.lcmlog", "CAMERA_RGBD only with --images");
  const test::RunResult r = run(dir_ / "camera.lcmlog", {"--images"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("/kestrel/camera/depth/image_raw: 3 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/kestrel/camera/rgb/camera_info: 3 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/kestrel/camera/rgb/image_raw: 3 messages\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/tf_static: 1 messages\n"), std::string::npos) << r.out;
}

TEST_F(BagExportTool, AFailedExportKeepsTheFileItWouldHaveReplaced) {
  { std::ofstream(bag()) << "kept"; }
  const test::RunResult r = run(dir_ / "absent.lcmlog");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(test::read_file(bag()), "kept");
}

TEST_F(BagExportTool, UsageErrors) {
  const std::string tool = test::tool("bag-export").string();
  EXPECT_EQ(test::run({tool, (dir_ / "in.lcmlog").string()}).exit_code, 2);  // no --bag
  EXPECT_EQ(test::run({tool, "--bag", bag().string()}).exit_code, 2);        // no log
  EXPECT_EQ(run(dir_ / "in.lcmlog", {"--no-such-option"}).exit_code, 2);
  EXPECT_FALSE(fs::exists(bag()));
}

// What EveryTool.* (common_tools_cli_test) checks of the multi-call tools, for this one.
TEST_F(BagExportTool, PrintedConfigReadsBackTheSameAndRunsTheSame) {
  test::write_state_log(dir_ / "in.lcmlog", 5, true);
  const std::string tool = test::tool("bag-export").string();
  const test::RunResult printed = test::run({tool, (dir_ / "in.lcmlog").string(), "--bag", bag().string(),
                                             "--world-frame", "odom", "--camera-frame", "rgb", "--print-config"});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  EXPECT_FALSE(fs::exists(bag()));
  std::ofstream(dir_ / "a.ini") << printed.out;
  const test::RunResult again = test::run({tool, "--config", (dir_ / "a.ini").string(), "--print-config"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out, printed.out);
  const test::RunResult r = test::run({tool, "--config", (dir_ / "a.ini").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames: odom -> base_link -> rgb\n"), std::string::npos) << r.out;
  std::ofstream(dir_ / "b.ini") << printed.out << "no-such-option = 1\n";
  EXPECT_EQ(test::run({tool, "--config", (dir_ / "b.ini").string()}).exit_code, 2);
}

}  // namespace
}  // namespace kestrel
