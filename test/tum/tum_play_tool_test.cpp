// kestrel-tum-play as a process: the log it writes, its exit codes and one-line errors for
// bad input, and live publishing inside a private network namespace (a LiveSystem,
// test/support/live_system.h, which hears the messages itself).

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <functional>
#include <map>

#include "common/time.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "test/support/live_system.h"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel {
namespace {

using test::TumFixture;

std::string play() { return test::tool("tum-play").string(); }

// Events of an LCM log, by channel, checking on the way that event times never go back and
// equal each message's utime.
struct LogContents {
  std::map<std::string, int> count;
  std::vector<transport::LogEvent> events;
};

LogContents read_log(const std::filesystem::path& path) {
  LogContents c;
  transport::LogReader reader(path.string());
  while (auto e = reader.next()) {
    ++c.count[e->channel];
    c.events.push_back(std::move(*e));
  }
  EXPECT_EQ(reader.damage_report(), "");
  return c;
}

TEST(TumPlayTool, WritesEveryMessageToTheLogInTimeOrder) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 4);
  const auto log = dir / "out.lcmlog";
  const auto r = test::run({play(), fx.folder().string(), "--log", log.string(), "--depth-encoding", "zstd"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames published: 4\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unmatched RGB frames: 0\n"), std::string::npos);
  EXPECT_NE(r.out.find("unused depth frames: 0\n"), std::string::npos);
  EXPECT_NE(r.out.find("time taken: "), std::string::npos);

  const LogContents c = read_log(log);
  EXPECT_EQ(c.count.at(channel::kCameraRgbd), 4);
  EXPECT_EQ(c.count.at(channel::kImu), 20);
  EXPECT_EQ(c.count.at(channel::kGroundTruth), 21);  // t0 - 50 ms .. t0 + 150 ms: 50 ms beyond the frames on each side
  EXPECT_EQ(c.count.size(), 3u);  // no heartbeats: nothing but the data goes into the log
  int frame = 0;
  for (size_t i = 0; i < c.events.size(); ++i) {
    const auto& e = c.events[i];
    if (i > 0) {
      ASSERT_GE(e.timestamp, c.events[i - 1].timestamp);
    }
    if (e.channel == channel::kCameraRgbd) {
      const auto m = transport::decode_message<kestrel::rgbd_frame_t>(e.data.data(), e.data.size(), e.channel);
      EXPECT_EQ(m.depth_encoding, kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD);
      const RgbdFrame f = transport::decode_rgbd(m, "log");
      EXPECT_EQ(e.timestamp, f.utime);
      EXPECT_EQ(f.seq, frame);
      EXPECT_EQ(f.rgb.at<cv::Vec3b>(300, 200), TumFixture::rgb_at(frame, 300, 200));
      EXPECT_EQ(f.depth_mm.at<uint16_t>(300, 200), (TumFixture::depth_raw_at(frame, 300, 200) + 2) / 5);
      ++frame;
    } else if (e.channel == channel::kImu) {
      EXPECT_EQ(e.timestamp, (transport::decode_message<kestrel::imu_t>(e.data.data(), e.data.size(), "IMU").utime));
    } else {
      EXPECT_EQ(e.timestamp,
                (transport::decode_message<kestrel::ground_truth_t>(e.data.data(), e.data.size(), "GT").utime));
    }
  }
}

TEST(TumPlayTool, BadInputExitsThreeWithOneLineNamingTheFileAndLine) {
  struct Case {
    const char* what;
    std::function<void(const TumFixture&)> damage;
    std::string expect;  // after "<folder>/"
  };
  const std::string rgb1 = "rgb/" + format_seconds(TumFixture::rgb_utime(1)) + ".png";
  const std::vector<Case> cases = {
      {"malformed rgb.txt line", [](const TumFixture& f) { f.edit_line("rgb.txt", 4, "1305031229.528748"); },
       "rgb.txt:4: expected 'timestamp filename'"},
      {"out-of-order depth.txt", [](const TumFixture& f) { f.edit_line("depth.txt", 5, "1305031229.000001 depth/x.png"); },
       "depth.txt:5: timestamp 1305031229.000001 is not after the previous one"},
      {"missing image", [&](const TumFixture& f) { std::filesystem::remove(f / rgb1); },
       "rgb.txt:5: listed image '" + rgb1 + "' does not exist"},
      {"corrupt image", [&](const TumFixture& f) { test::write_text(f / rgb1, "garbage"); },
       "rgb.txt:5: " },
      {"NaN in the accelerometer log", [](const TumFixture& f) { f.edit_line("accelerometer.txt", 6, "1305031229.438748 0 nan 1"); },
       "accelerometer.txt:6: non-finite acceleration"},
      {"malformed ground truth", [](const TumFixture& f) { f.edit_line("groundtruth.txt", 4, "1305031229.428748 1 2 3"); },
       "groundtruth.txt:4: expected 'timestamp tx ty tz qx qy qz qw'"},
      {"missing rgb.txt", [](const TumFixture& f) { std::filesystem::remove(f / "rgb.txt"); },
       "rgb.txt: cannot open image list"},
  };
  for (const Case& c : cases) {
    test::TempDir dir;
    const TumFixture fx(dir.path(), 2);
    c.damage(fx);
    const auto r = test::run({play(), fx.folder().string(), "--log", (dir / "x.lcmlog").string(), "-q"});
    EXPECT_EQ(r.exit_code, 3) << c.what << ": " << r.err;
    const std::string expected = "kestrel-tum-play: error: " + fx.folder().string() + "/" + c.expect;
    EXPECT_EQ(r.err.rfind(expected, 0), 0u) << c.what << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.what << ": " << r.err;
  }
  test::TempDir dir;
  const auto r = test::run({play(), (dir / "nowhere").string(), "--log", (dir / "x.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.err, "kestrel-tum-play: error: " + (dir / "nowhere").string() + ": no such sequence folder\n");
}

// Nothing to play is bad input (exit 3), not a run that publishes 0 frames and exits 0.
TEST(TumPlayTool, NoPairedFrameExitsThreeNamingTheFolderAndTolerance) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 2);  // depth 1 ms after RGB
  const auto r = test::run({play(), fx.folder().string(), "--log", (dir / "x.lcmlog").string(), "--max-dt",
                            "0.0005", "-q"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("kestrel-tum-play: error: " + fx.folder().string() + ": no RGB image has a depth image", 0),
            0u)
      << r.err;
  EXPECT_NE(r.err.find("association tolerance of 0.000500 s"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.lcmlog")) << "a log of nothing was written";
}

TEST(TumPlayTool, BadOptionsExitTwo) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 2);
  const std::string log = (dir / "x.lcmlog").string();
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--log", log, "--loop"},
           {"--log", log, "--start", "100"},
           {"--rate", "0"},
           {"--log", log, "--intrinsics", "500,500,320"},
           {"--log", log, "--intrinsics", "-5,500,320,240"},
           {"--log", log, "--rgb-encoding", "png"},
       }) {
    std::vector<std::string> argv = {play(), fx.folder().string()};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto r = test::run(argv);
    EXPECT_EQ(r.exit_code, 2) << args.back() << ": " << r.err;
  }
  const auto help = test::run({play(), "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--depth-encoding"), std::string::npos);
}

TEST(TumPlayTool, PublishesLiveWithHeartbeatsInsideANetworkNamespace) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here: " << why;
  test::TempDir dir;
  const TumFixture fx(dir.path(), 3);
  const auto log = dir / "live.lcmlog";
  {
    // Listening (on kestrel's default URL, whose receive buffer takes whole frames) before the
    // player starts; what it sent is all heard once it has exited (finish()).
    test::LiveSystem live(dir / "processes", {{channel::kCameraRgbd, channel::kProcessStatus}, log, {}});
    const int rc = live.run("tum-play", {play(), fx.folder().string(), "--rate", "2", "--rgb-encoding", "jpeg"}, 120.0);
    live.finish();
    ASSERT_EQ(rc, 0) << live.output("tum-play");
  }
  const LogContents c = read_log(log);
  EXPECT_EQ(c.count.count(channel::kCameraRgbd) ? c.count.at(channel::kCameraRgbd) : 0, 3);
  EXPECT_GE(c.count.count(channel::kProcessStatus) ? c.count.at(channel::kProcessStatus) : 0, 1);
  int64_t previous = -1;
  for (const auto& e : c.events) {
    if (e.channel == channel::kProcessStatus) {
      const auto s = transport::decode_message<kestrel::process_status_t>(e.data.data(), e.data.size(), e.channel);
      EXPECT_EQ(s.name, "tum-play");
    } else if (e.channel == channel::kCameraRgbd) {
      const auto m = transport::decode_message<kestrel::rgbd_frame_t>(e.data.data(), e.data.size(), e.channel);
      EXPECT_EQ(m.rgb_encoding, kestrel::rgbd_frame_t::RGB_JPEG);
      EXPECT_GT(m.seq, previous);
      previous = m.seq;
    }
  }
}

TEST(TumPlayTool, SigintEndsALoopedPlaybackWithCode130) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here: " << why;
  test::TempDir dir;
  const TumFixture fx(dir.path(), 2);
  test::LiveSystem live(dir / "processes", {{channel::kCameraRgbd}, {}, {}});
  live.start("tum-play", {play(), fx.folder().string(), "--loop", "-q"});
  // Interrupted in its second pass over the two frames.
  int frames = 0;
  ASSERT_TRUE(live.wait_for<kestrel::rgbd_frame_t>(
      channel::kCameraRgbd, [&](const kestrel::rgbd_frame_t&) { return ++frames == 3; }, 30.0,
      "the looped playback's third frame"))
      << live.output("tum-play");
  const int rc = live.stop("tum-play", SIGINT);
  const std::string out = live.output("tum-play");
  EXPECT_EQ(rc, 130) << out;
  EXPECT_NE(out.find("frames published: "), std::string::npos) << out;
}

}  // namespace
}  // namespace kestrel
