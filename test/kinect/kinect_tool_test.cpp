// kestrel-kinect and kestrel-tum-to-fakenect as processes, on TUM folders written by the test:
// a fakenect recording made from known frames, replayed through Debian's fakenect library by
// the unchanged driver, must come back as those frames. Also the driver's exit codes when
// there is no device or no recording. Live publishing runs inside a private network namespace
// under a LiveSystem (test/support/live_system.h), which hears the messages itself.

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <filesystem>
#include <fstream>
#include <set>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/kinect/accelerometer.h"
#include "drivers/kinect/disparity_model.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "test/kinect/fakenect_support.h"
#include "test/support/live_system.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel {
namespace {

using test::TumFixture;

TEST(KinectTool, IdentityCalibrationRoundTripIsExactWithinQuantisation) {
  KESTREL_REQUIRE_FAKENECT();
  test::TempDir dir;
  const TumFixture fx(dir.path(), 5);
  const auto dump = dir / "dump";
  const auto w = test::run({test::tool("tum-to-fakenect").string(), fx.folder().string(), dump.string(),
                            "--identity-calibration"});
  ASSERT_EQ(w.exit_code, 0) << w.err;
  EXPECT_NE(w.out.find("frames written: 5\n"), std::string::npos) << w.out;

  const auto log = dir / "kinect.lcmlog";
  const auto r = test::run_kinect(dump, {"--config", (dump / "kestrel-kinect.ini").string(), "--log", log.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames published: 5\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dropped rgb 0, dropped depth 0"), std::string::npos) << r.out;

  const kinect::DisparityModel model;
  std::set<std::vector<double>> accel_expected;
  for (int i = 0; i < fx.accel_samples(); ++i) {
    const cv::Vec3d a = TumFixture::accel_at(i);
    const Eigen::Vector3d c = kinect::accel_to_camera({a[0], a[1], a[2]});
    accel_expected.insert({std::round(c.x() * 1e6), std::round(c.y() * 1e6), std::round(c.z() * 1e6)});
  }
  int frame = 0, imu = 0;
  transport::LogReader reader(log.string());
  while (auto e = reader.next()) {
    if (e->channel == channel::kImu) {
      const auto m = transport::decode_message<kestrel::imu_t>(e->data.data(), e->data.size(), e->channel);
      EXPECT_EQ(m.fields, kestrel::imu_t::HAS_ACCEL);
      const std::vector<double> key = {std::round(m.linear_acceleration[0] * 1e6),
                                       std::round(m.linear_acceleration[1] * 1e6),
                                       std::round(m.linear_acceleration[2] * 1e6)};
      EXPECT_TRUE(accel_expected.count(key)) << m.linear_acceleration[0] << " " << m.linear_acceleration[1];
      ++imu;
      continue;
    }
    ASSERT_EQ(e->channel, channel::kCameraRgbd);
    const RgbdFrame f = transport::decode_rgbd(
        transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), e->channel), "log");
    EXPECT_EQ(f.seq, frame);
    EXPECT_EQ(f.camera.fx, 517.3);  // the fixture folder names freiburg1
    EXPECT_EQ(f.sensor, "kinect1");  // the driver's, whatever the replayed folder's name
    EXPECT_EQ(cv::norm(f.rgb, TumFixture::rgb_image(frame), cv::NORM_INF), 0.0) << "frame " << frame;
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const int expected = (TumFixture::depth_raw_at(frame, v, u) + 2) / 5;
        const int got = f.depth_mm.at<uint16_t>(v, u);
        if (expected == 0) {
          ASSERT_EQ(got, 0) << v << "," << u;
        } else {
          ASSERT_NEAR(got, expected, 0.5 * model.step_at(expected * 1e-3) * 1e3 + 1.0) << v << "," << u;
        }
      }
    }
    ++frame;
  }
  EXPECT_EQ(frame, 5);
  EXPECT_GT(imu, 5);  // 100 Hz over about 0.2 s
}

TEST(KinectTool, ADroppedFrameIsCountedAndTheRestPublished) {
  KESTREL_REQUIRE_FAKENECT();
  test::TempDir dir;
  const TumFixture fx(dir.path(), 5);
  const auto dump = dir / "dump";
  ASSERT_EQ(test::run({test::tool("tum-to-fakenect").string(), fx.folder().string(), dump.string(), "--no-accel"}).exit_code, 0);
  // Remove the third RGB frame from the index, as if the USB link had lost it.
  std::ifstream in(dump / "INDEX.txt");
  std::string kept;
  int rgb = 0;
  for (std::string line; std::getline(in, line);) {
    if (line[0] == 'r' && rgb++ == 2) continue;
    kept += line + "\n";
  }
  in.close();
  test::write_text(dump / "INDEX.txt", kept);
  const auto r = test::run_kinect(dump, {"--config", (dump / "kestrel-kinect.ini").string(), "--log",
                                         (dir / "k.lcmlog").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames published: 4\n"), std::string::npos) << r.out;
  // Its depth frame has no RGB partner left and is reported unused.
  EXPECT_NE(r.out.find("unused depth 1, shared depth 0, dropped rgb 1, dropped depth 0"), std::string::npos) << r.out;
}

// A folder whose camera.txt gives another image size cannot become a Kinect's dump (640x480):
// exit 3 naming the size before anything is written.
TEST(KinectTool, AFolderOfAnotherImageSizeIsRefusedBeforeAnythingIsWritten) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 2);
  test::write_text(fx / "camera.txt", "262.5 262.5 159.5 119.5 320 240\n");
  const auto dump = dir / "dump";
  const auto r = test::run({test::tool("tum-to-fakenect").string(), fx.folder().string(), dump.string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("the images are 320x240 (its camera.txt), a Kinect dump is 640x480"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dump)) << "nothing written";
}

TEST(KinectTool, PublishesLiveWithHeartbeatsInsideANetworkNamespace) {
  KESTREL_REQUIRE_FAKENECT();
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here: " << why;
  test::TempDir dir;
  const TumFixture fx(dir.path(), 3);
  const auto dump = dir / "dump";
  ASSERT_EQ(test::run({test::tool("tum-to-fakenect").string(), fx.folder().string(), dump.string()}).exit_code, 0);
  const auto log = dir / "live.lcmlog";
  {
    // Listening before the driver starts; what it sent is all heard once it has exited.
    test::LiveSystem live(dir / "processes", {{channel::kCameraRgbd, channel::kProcessStatus}, log, {}});
    const int rc = live.run("kinect",
                            {"env", "LD_LIBRARY_PATH=" + test::fakenect_library_dir(), "FAKENECT_PATH=" + dump.string(),
                             test::tool("kinect").string(), "--config", (dump / "kestrel-kinect.ini").string(),
                             "--depth-encoding", "zstd"},
                            120.0);
    live.finish();
    ASSERT_EQ(rc, 0) << live.output("kinect");
  }
  transport::LogReader reader(log.string());
  int frames = 0, heartbeats = 0;
  while (auto e = reader.next()) {
    if (e->channel == channel::kCameraRgbd) {
      const RgbdFrame f = transport::decode_rgbd(
          transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), e->channel), "live");
      EXPECT_EQ(cv::norm(f.rgb, TumFixture::rgb_image(frames), cv::NORM_INF), 0.0);
      ++frames;
    } else if (e->channel == channel::kProcessStatus) {
      const auto s = transport::decode_message<kestrel::process_status_t>(e->data.data(), e->data.size(), e->channel);
      EXPECT_EQ(s.name, "kinect");
      ++heartbeats;
    }
  }
  EXPECT_EQ(frames, 3);
  EXPECT_GE(heartbeats, 1);
}

TEST(KinectTool, NoDeviceExitsUnavailable) {
  // The real libfreenect, and no Kinect on this machine.
  test::TempDir dir;
  const auto r = test::run({test::tool("kinect").string(), "--log", (dir / "k.lcmlog").string()});
  if (r.exit_code == 0) KESTREL_SKIP_ENVIRONMENT() << "a Kinect is plugged in here";
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_NE(r.err.find("kestrel-kinect: error: "), std::string::npos) << r.err;
  EXPECT_TRUE(r.err.find("no Kinect found") != std::string::npos ||
              r.err.find("cannot initialise libfreenect") != std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "k.lcmlog"));  // nothing written without a device
}

TEST(KinectTool, MissingRecordingIsAClearInputError) {
  KESTREL_REQUIRE_FAKENECT();
  test::TempDir dir;
  const auto missing = dir / "no-such-dump";
  auto r = test::run_kinect(missing, {"--log", (dir / "k.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err, "kestrel-kinect: error: " + missing.string() + ": not a fakenect dump (no INDEX.txt)\n");
  r = test::run({"env", "-u", "FAKENECT_PATH", "LD_LIBRARY_PATH=" + test::fakenect_library_dir(),
                 test::tool("kinect").string(), "--log", (dir / "k.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("FAKENECT_PATH is not set"), std::string::npos) << r.err;
}

TEST(KinectTool, BadOptionsExitTwo) {
  test::TempDir dir;
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--frames", "-1"},
           {"--body-camera-pose", "0,0,0,2,0,0,0"},
           {"--rgb-in-ir-rotation", "1,0,0,0,1,0,0,0,-1"},
           {"--depth-encoding", "png"},
       }) {
    std::vector<std::string> argv = {test::tool("kinect").string(), "--log", (dir / "k.lcmlog").string()};
    argv.insert(argv.end(), args.begin(), args.end());
    EXPECT_EQ(test::run(argv).exit_code, 2) << args[0];
  }
  const auto w = test::run({test::tool("tum-to-fakenect").string(), (dir / "nowhere").string(), (dir / "out").string()});
  EXPECT_EQ(w.exit_code, 3);
  EXPECT_EQ(w.err, "kestrel-tum-to-fakenect: error: " + (dir / "nowhere").string() + ": no such sequence folder\n");
}

}  // namespace
}  // namespace kestrel
