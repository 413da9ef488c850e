// kestrel-replay against real processes, inside a private network namespace: a chain of two
// codecs (CAMERA_RGBD -> codec-z -> CAMERA_RGBD_Z -> codec-raw -> CAMERA_RGBD_RAW).

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/rgbd_frame_t.hpp"
#include "test/replay/fixtures.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

using kestrel::rgbd_frame_t;

class LockstepReplay : public ::testing::Test {
 protected:
  void SetUp() override { KESTREL_REQUIRE_ISOLATION(); }

  std::unique_ptr<Background> codec(const std::string& name, const std::string& in,
                                    const std::string& out, const std::string& encoding) {
    const bool raw = encoding == "raw";
    return std::make_unique<Background>(
        std::vector<std::string>{tool("rgbd-codec"), "--name", name, "--in", in, "--out", out,
                                 "--rgb", raw ? "raw" : "jpeg", "--depth", raw ? "raw" : "zstd"},
        dir.path(), name);
  }
  void start_chain() {
    codec_z = codec("codec-z", "CAMERA_RGBD", "CAMERA_RGBD_Z", "compressed");
    codec_raw = codec("codec-raw", "CAMERA_RGBD_Z", "CAMERA_RGBD_RAW", "raw");
  }
  // kestrel-replay with the chain expected and a short settling time.
  RunResult replay(std::vector<std::string> args, double timeout_s = 60.0) {
    std::vector<std::string> argv{tool("replay"), "--settle", "0.5", "--json"};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv, timeout_s);
  }
  static nlohmann::json report(const RunResult& r) {
    try {
      return nlohmann::json::parse(r.out);
    } catch (const std::exception&) {
      ADD_FAILURE() << "no JSON report; stdout:\n" << r.out << "\nstderr:\n" << r.err;
      return {};
    }
  }

  TempDir dir;
  std::unique_ptr<Background> codec_z, codec_raw;
};

TEST_F(LockstepReplay, TwoReplaysThroughTheChainRecordIdenticalBytes) {
  TestLogSpec spec;
  spec.frames = 40;
  spec.width = 96;
  spec.height = 72;
  const auto counts = write_test_log(dir / "in.lcmlog", spec);
  const int64_t total = counts.at("CAMERA_RGBD") + counts.at("IMU") + counts.at("GROUND_TRUTH");

  start_chain();
  const std::vector<std::string> expect{"--expect", "codec-z,codec-raw"};
  auto args = [&](const std::string& out) {
    std::vector<std::string> a{(dir / "in.lcmlog").string(), "--record", (dir / out).string()};
    a.insert(a.end(), expect.begin(), expect.end());
    return a;
  };
  const RunResult first = replay(args("fresh.lcmlog"));  // processes just started
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const RunResult second = replay(args("reused.lcmlog"));  // the same processes, after RESET
  ASSERT_EQ(second.exit_code, 0) << second.err;

  const auto j = report(first);
  EXPECT_EQ(j["events_replayed"], total);
  EXPECT_EQ(j["record"]["messages"], 2 * spec.frames);
  EXPECT_EQ(j["record"]["unannounced"], 0);
  EXPECT_EQ(j["processes"].size(), 2u);

  const auto fresh = read_bytes(dir / "fresh.lcmlog");
  ASSERT_FALSE(fresh.empty());
  EXPECT_TRUE(fresh == read_bytes(dir / "reused.lcmlog")) << "the two recordings differ";

  // Known answers: per frame, Z then RAW, stamped with the frame's time; depth exact after
  // the lossless round trip, colour close after JPEG.
  const auto outputs = read_log(dir / "fresh.lcmlog");
  ASSERT_EQ(outputs.size(), static_cast<size_t>(2 * spec.frames));
  for (int i = 0; i < spec.frames; ++i) {
    const auto& z = outputs[2 * i];
    const auto& raw = outputs[2 * i + 1];
    ASSERT_EQ(z.channel, "CAMERA_RGBD_Z");
    ASSERT_EQ(raw.channel, "CAMERA_RGBD_RAW");
    const int64_t t = spec.start_utime + i * spec.frame_period_us;
    EXPECT_EQ(z.timestamp, t);
    EXPECT_EQ(raw.timestamp, t);
    const auto msg = transport::decode_message<rgbd_frame_t>(raw.data.data(), raw.data.size(), "RAW");
    EXPECT_EQ(msg.rgb_encoding, rgbd_frame_t::RGB_RGB8);
    EXPECT_EQ(msg.seq, i);
    const RgbdFrame got = transport::decode_rgbd(msg, "RAW");
    const RgbdFrame want = synthetic_frame(i, spec.width, spec.height);
    EXPECT_EQ(cv::norm(got.depth_mm, want.depth_mm, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_GT(cv::PSNR(got.rgb, want.rgb), 23.0) << "frame " << i;
  }
}

TEST_F(LockstepReplay, AKilledConsumerIsAnAckTimeoutNamingItNotAHang) {
  TestLogSpec spec;
  spec.frames = 600;
  spec.width = 32;
  spec.height = 24;
  spec.imu_per_frame = 0;
  spec.ground_truth = false;
  write_test_log(dir / "long.lcmlog", spec);
  start_chain();
  LcmTap tap;
  const pid_t victim = codec_raw->pid();
  tap.set_hook([victim](const std::string& channel, int64_t n) {
    if (channel == "CAMERA_RGBD_RAW" && n == 5) ::kill(victim, SIGKILL);
  });
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = replay({(dir / "long.lcmlog").string(), "--expect", "codec-z,codec-raw",
                              "--ack-timeout", "1.5"});
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("codec-raw did not acknowledge 1 CAMERA_RGBD_Z input(s)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(CAMERA_RGBD at 1000."), std::string::npos) << r.err;  // the event's time
  EXPECT_NE(r.err.find("no progress for 1.5 s"), std::string::npos) << r.err;
  EXPECT_LT(elapsed, 10.0);  // discovery + a few events + 1.5 s, with a wide margin
  EXPECT_EQ(codec_raw->wait_exit(1.0), 128 + SIGKILL);
}

TEST_F(LockstepReplay, ADamagedLogIsReplayedAroundTheDamageAndSaysSo) {
  TestLogSpec spec;
  spec.frames = 20;
  spec.imu_per_frame = 0;
  spec.ground_truth = false;
  write_test_log(dir / "good.lcmlog", spec);
  auto bytes = read_bytes(dir / "good.lcmlog");
  const size_t event_size = bytes.size() / spec.frames;  // raw frames: all the same size
  bytes[7 * event_size] ^= 0xff;                          // sync word of event 7
  bytes.resize(bytes.size() - 100);                       // and the last event cut short
  write_bytes(dir / "damaged.lcmlog", bytes);

  start_chain();
  const RunResult r = replay({(dir / "damaged.lcmlog").string(), "--record",
                              (dir / "out.lcmlog").string(), "--expect", "codec-z,codec-raw"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = report(r);
  EXPECT_EQ(j["events_replayed"], spec.frames - 2);
  EXPECT_EQ(j["record"]["messages"], 2 * (spec.frames - 2));
  const std::string damage = j["damage"];
  EXPECT_NE(damage.find("damaged.lcmlog: damaged LCM log: 1 corrupt region(s), truncated last event"),
            std::string::npos) << damage;
  EXPECT_NE(r.err.find("damaged LCM log"), std::string::npos) << "the damage must also be warned about";
}

TEST_F(LockstepReplay, SkipsChannelsALiveProcessPublishesUnlessSelected) {
  {
    transport::LogWriter w(dir / "mixed.lcmlog");
    transport::RgbdEncoding z;
    z.rgb = rgbd_frame_t::RGB_JPEG;
    z.depth = rgbd_frame_t::DEPTH_U16_MM_ZSTD;
    for (int i = 0; i < 5; ++i) {
      const RgbdFrame f = synthetic_frame(i);
      w.write_message("CAMERA_RGBD", f.utime, transport::encode_rgbd(f));
      w.write_message("CAMERA_RGBD_Z", f.utime, transport::encode_rgbd(f, z));
    }
    w.close();
  }
  codec_z = codec("codec-z", "CAMERA_RGBD", "CAMERA_RGBD_Z", "compressed");
  const RunResult r = replay({(dir / "mixed.lcmlog").string(), "--expect", "codec-z"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = report(r);
  EXPECT_EQ(j["replayed"]["CAMERA_RGBD"], 5);
  EXPECT_EQ(j["skipped"]["CAMERA_RGBD_Z"]["events"], 5);
  EXPECT_EQ(j["skipped"]["CAMERA_RGBD_Z"]["reason"], "published by live process codec-z");

  const RunResult selected = replay({(dir / "mixed.lcmlog").string(), "--expect", "codec-z",
                                     "--channels", "CAMERA_RGBD_Z"});
  ASSERT_EQ(selected.exit_code, 0) << selected.err;
  j = report(selected);
  EXPECT_EQ(j["replayed"]["CAMERA_RGBD_Z"], 5);
  EXPECT_EQ(j["skipped"]["CAMERA_RGBD"]["reason"], "not selected by --channels");
}

TEST_F(LockstepReplay, AMissingExpectedProcessIsNamedAfterTheDiscoveryTimeout) {
  write_test_log(dir / "in.lcmlog", {});
  codec_z = codec("codec-z", "CAMERA_RGBD", "CAMERA_RGBD_Z", "compressed");
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = replay({(dir / "in.lcmlog").string(), "--expect", "codec-z,ghost",
                              "--discovery-timeout", "1.5"});
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no heartbeat within 1.5 s from: ghost (heard from: codec-z)"),
            std::string::npos) << r.err;
  EXPECT_LT(elapsed, 6.0);
}

TEST_F(LockstepReplay, TwoProcessesWithOneNameAreRefused) {
  write_test_log(dir / "in.lcmlog", {});
  codec_z = codec("twin", "CAMERA_RGBD", "A", "compressed");
  codec_raw = codec("twin", "CAMERA_RGBD", "B", "raw");
  const RunResult r = replay({(dir / "in.lcmlog").string(), "--expect", "twin"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("several processes share a name"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("twin (pids "), std::string::npos) << r.err;
}

TEST_F(LockstepReplay, WithoutProcessesItReplaysIntoNothingAndWarns) {
  TestLogSpec spec;
  spec.frames = 3;
  write_test_log(dir / "in.lcmlog", spec);
  const RunResult r = replay({(dir / "in.lcmlog").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(report(r)["events_replayed"], 3 + 3 + 9);
  EXPECT_NE(r.err.find("no kestrel process answered"), std::string::npos) << r.err;
}

TEST_F(LockstepReplay, CtrlCEndsTheSessionAndExits130) {
  TestLogSpec spec;
  spec.frames = 3000;
  spec.width = 16;
  spec.height = 12;
  spec.imu_per_frame = 0;
  spec.ground_truth = false;
  write_test_log(dir / "long.lcmlog", spec);
  start_chain();
  LcmTap tap;
  Background replaying({tool("replay"), (dir / "long.lcmlog").string(), "--settle", "0.5",
                        "--expect", "codec-z,codec-raw"},
                       dir.path(), "replay");
  ASSERT_TRUE(tap.wait_until([&] { return tap.count("CAMERA_RGBD_RAW") >= 20; }, 30.0));
  replaying.signal(SIGINT);
  EXPECT_EQ(replaying.wait_exit(10.0), 130) << replaying.err();
  EXPECT_NE(replaying.out().find("(INTERRUPTED)"), std::string::npos) << replaying.out();
  EXPECT_TRUE(codec_z->wait_for_output("ends", 5.0, /*in_stderr=*/true)) << codec_z->err();
}

TEST_F(LockstepReplay, BadInvocationsExitWithTheirCodes) {
  RunResult r = replay({(dir / "missing.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("missing.lcmlog: cannot open LCM log"), std::string::npos) << r.err;
  write_bytes(dir / "text.lcmlog", {'h', 'e', 'l', 'l', 'o'});
  r = replay({(dir / "text.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("text.lcmlog: not an LCM log"), std::string::npos) << r.err;
  write_test_log(dir / "in.lcmlog", {});
  r = replay({(dir / "in.lcmlog").string(), "--speed", "2", "--record", (dir / "o.lcmlog").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = replay({(dir / "in.lcmlog").string(), "--ack-timeout", "0"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
}

}  // namespace
}  // namespace kestrel::test
