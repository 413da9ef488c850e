// kestrel-bag-import as a user runs it: a good bag gives a log and a summary; each bad bag is
// one error line naming the topic (or the file), exit 3, and no log, not even a partial one.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>

#include <rosbag/bag.h>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "ros/ros_convert.h"
#include "test/ros/bag_writer.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;
constexpr int kW = 8, kH = 6;

// A bag of `frames` colour frames 33.333 ms apart with their depth 5 ms later, a CameraInfo
// per frame and an IMU sample every 5 ms; `change` edits it before it is written.
struct Spec {
  int frames = 5;
  std::string depth_encoding = "16UC1";
  bool depth_topic = true;
  double fx = 520.0;
  bool nan_imu = false;
};

void write_bag(const fs::path& path, const Spec& spec) {
  rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
  for (int i = 0; i < spec.frames; ++i) {
    const int64_t t = 1000000 + i * 33333;
    const ros::Time stamp = ros1::to_ros_time(t);
    bag.write("/camera/rgb/image_color", stamp, test::colour_image(t, kW, kH));
    bag.write("/camera/rgb/camera_info", stamp, test::camera_info(t, kW, kH, spec.fx, spec.fx));
    if (spec.depth_topic) {
      sensor_msgs::Image depth = test::depth_image_mm(t + 5000, kW, kH, 1500);
      depth.encoding = spec.depth_encoding;
      bag.write("/camera/depth/image", ros1::to_ros_time(t + 5000), depth);
    }
  }
  for (int i = 0; i < spec.frames * 6; ++i) {
    const int64_t t = 1000000 + i * 5000;
    sensor_msgs::Imu imu = test::accel_sample(t, {0.0, 9.8, 0.0});
    if (spec.nan_imu && i == 7) imu.linear_acceleration.z = std::nan("");
    bag.write("/imu", imu.header.stamp, imu);
  }
  bag.close();
}

class BagImportTool : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(test::tool("bag-import"))) {
      KESTREL_SKIP_ENVIRONMENT() << test::tool("bag-import") << " is not built (the ROS packages are missing)";
    }
  }
  test::RunResult import(const fs::path& bag) {
    return test::run({test::tool("bag-import").string(), bag.string(), "--log", log().string()}, 60.0);
  }
  fs::path log() const { return dir_ / "out.lcmlog"; }
  // Exit 3, one line "kestrel-bag-import: error: ..." holding `words`, and no log.
  void expect_refused(const Spec& spec, const std::string& words) {
    write_bag(dir_ / "bad.bag", spec);
    expect_refused_bag(dir_ / "bad.bag", words);
  }
  void expect_refused_bag(const fs::path& bag, const std::string& words) {
    const test::RunResult r = import(bag);
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_EQ(r.err.rfind("kestrel-bag-import: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(log())) << "a failed import left " << log();
    for (const auto& e : fs::directory_iterator(dir_.path()))
      EXPECT_EQ(e.path().filename().string().find(".out.lcmlog.tmp"), std::string::npos) << "temporary left: " << e.path();
  }
  test::TempDir dir_;
};

TEST_F(BagImportTool, GoodBagGivesTheLogAndASummary) {
  write_bag(dir_ / "good.bag", {});
  const test::RunResult r = import(dir_ / "good.bag");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames written: 5 (colour images 5, depth images 5)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("IMU samples written: 30 (0 measuring nothing, skipped; axes as published)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ground-truth poses written: 0 (none: no /tf topic)\n"), std::string::npos) << r.out;
  size_t frames = 0, imu = 0;
  int64_t last = 0;
  transport::LogReader reader(log().string());
  while (auto e = reader.next()) {
    frames += e->channel == channel::kCameraRgbd;
    imu += e->channel == channel::kImu;
    EXPECT_GE(e->timestamp, last) << "events out of time order";
    last = e->timestamp;
  }
  EXPECT_EQ(frames, 5u);
  EXPECT_EQ(imu, 30u);
}

TEST_F(BagImportTool, NoDepthTopic) {
  Spec s;
  s.depth_topic = false;
  expect_refused(s, "/camera/depth/image: no such topic");
}

TEST_F(BagImportTool, DepthEncodingItDoesNotKnow) {
  Spec s;
  s.depth_encoding = "8UC1";
  expect_refused(s, "/camera/depth/image at 1.005000 s: depth encoding '8UC1' is not one kestrel reads");
}

TEST_F(BagImportTool, TruncatedBag) {
  write_bag(dir_ / "whole.bag", {});
  const std::string bytes = test::read_file(dir_ / "whole.bag");
  ASSERT_GT(bytes.size(), 1000u);
  // Cut in the middle of the data: the index at the end is gone.
  std::ofstream(dir_ / "cut.bag", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  expect_refused_bag(dir_ / "cut.bag", (dir_ / "cut.bag").string() + ": cannot read the bag: it ends early or is damaged");
}

TEST_F(BagImportTool, DamagedConnectionRecordIsOneErrorLine) {
  write_bag(dir_ / "whole.bag", {});
  std::string bytes = test::read_file(dir_ / "whole.bag");
  // The connection records at the end of the file (the index librosbag reads) name each
  // topic's type as "type=..."; without its '=' the record is damaged. librosbag reports that
  // on its own console before it throws: kestrel's one line must be all the user sees.
  const size_t at = bytes.rfind("type=sensor_msgs/Image");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 4] = 'X';
  std::ofstream(dir_ / "damaged.bag", std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  expect_refused_bag(dir_ / "damaged.bag", "not a ROS 1 bag, or a damaged one");
  const test::RunResult r = import(dir_ / "damaged.bag");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(BagImportTool, CameraInfoWithZeroFocalLength) {
  Spec s;
  s.fx = 0.0;
  expect_refused(s, "/camera/rgb/camera_info at 1.000000 s: CameraInfo focal length");
}

TEST_F(BagImportTool, NanInAnImuMessage) {
  Spec s;
  s.nan_imu = true;
  expect_refused(s, "/imu at 1.035000 s: Imu linear_acceleration is not finite");
}

TEST_F(BagImportTool, AFailedImportKeepsTheFileItWouldHaveReplaced) {
  { std::ofstream(log()) << "kept"; }
  Spec s;
  s.depth_topic = false;
  write_bag(dir_ / "bad.bag", s);
  const test::RunResult r = import(dir_ / "bad.bag");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(test::read_file(log()), "kept");
}

// What EveryTool.* (common_tools_cli_test) checks of the multi-call tools, for this one.
TEST_F(BagImportTool, PrintedConfigReadsBackTheSameAndRunsTheSame) {
  write_bag(dir_ / "good.bag", {});
  const std::string tool = test::tool("bag-import").string();
  const test::RunResult printed = test::run({tool, (dir_ / "good.bag").string(), "--log", log().string(), "--max-dt",
                                             "0.01", "--imu-topic", "", "--intrinsics", "500,500,3.5,2.5", "--print-config"});
  ASSERT_EQ(printed.exit_code, 0) << printed.err;
  std::ofstream(dir_ / "a.ini") << printed.out;
  const test::RunResult again = test::run({tool, "--config", (dir_ / "a.ini").string(), "--print-config"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out, printed.out);
  const test::RunResult run = test::run({tool, "--config", (dir_ / "a.ini").string()});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("camera: 8x6, fx=500 fy=500 cx=3.5 cy=2.5, from --intrinsics\n"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("IMU samples written: 0 "), std::string::npos) << run.out;
  std::ofstream(dir_ / "b.ini") << printed.out << "no-such-option = 1\n";
  EXPECT_EQ(test::run({tool, "--config", (dir_ / "b.ini").string()}).exit_code, 2);
}

TEST_F(BagImportTool, MissingBagAndMissingLogOptionAreInputAndUsageErrors) {
  const test::RunResult missing = import(dir_ / "absent.bag");
  EXPECT_EQ(missing.exit_code, 3) << missing.err;
  EXPECT_NE(missing.err.find("absent.bag"), std::string::npos) << missing.err;
  const test::RunResult usage = test::run({test::tool("bag-import").string(), (dir_ / "absent.bag").string()});
  EXPECT_EQ(usage.exit_code, 2) << usage.err;
}

}  // namespace
}  // namespace kestrel
