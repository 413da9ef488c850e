// The merged, time-ordered playback of a sequence (playback.h) and the player that turns it
// into messages (player.h), in process.

#include <gtest/gtest.h>

#include <algorithm>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "drivers/tum/playback.h"
#include "drivers/tum/player.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "test/support/test_support.h"
#include "test/tum/tum_fixture.h"

namespace kestrel::tum {
namespace {

using test::TumFixture;

struct Published {
  std::string channel;
  int64_t utime;
  std::vector<uint8_t> bytes;
};

PlayerSink collect(std::vector<Published>& out) {
  PlayerSink sink;
  sink.publish = [&out](const std::string& c, int64_t t, const std::vector<uint8_t>& b) {
    out.push_back({c, t, b});
  };
  return sink;
}

TEST(Playback, MergesFramesImuAndGroundTruthInTimeOrder) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 4);
  const TumSequence s(fx.folder().string());
  const auto events = playback_schedule(s, {});
  int frames = 0, imu = 0, gt = 0;
  for (size_t i = 0; i < events.size(); ++i) {
    if (i > 0) {
      ASSERT_LE(events[i - 1].utime, events[i].utime);
      if (events[i - 1].utime == events[i].utime) {
        ASSERT_LT(static_cast<int>(events[i - 1].kind), static_cast<int>(events[i].kind));
      }
    }
    frames += events[i].kind == EventKind::kFrame;
    imu += events[i].kind == EventKind::kImu;
    gt += events[i].kind == EventKind::kGroundTruth;
  }
  EXPECT_EQ(frames, 4);
  // Between the first and last frame (0 .. 99999 us after t0), inclusive: the accelerometer
  // every 5 ms from t0 - 0.1 s hits t0 exactly. Ground truth, every 10 ms from t0 - 0.1 s,
  // reaches 50 ms beyond the frames on both sides (an image's capture can precede its stamp).
  EXPECT_EQ(imu, 20);  // t0, t0 + 5 ms, ..., t0 + 95 ms
  EXPECT_EQ(gt, 21);   // t0 - 50 ms, t0 - 40 ms, ..., t0 + 150 ms
  EXPECT_EQ(events.front().utime, TumFixture::kT0 - kGroundTruthMarginUs);
  EXPECT_EQ(events.front().kind, EventKind::kGroundTruth);
  const auto at_t0 = std::find_if(events.begin(), events.end(), [](const PlaybackEvent& e) { return e.utime == TumFixture::kT0; });
  ASSERT_NE(at_t0, events.end());
  EXPECT_EQ(at_t0[0].kind, EventKind::kImu);  // IMU before ground truth before the frame
  EXPECT_EQ(at_t0[1].kind, EventKind::kGroundTruth);
  EXPECT_EQ(at_t0[2].kind, EventKind::kFrame);
  EXPECT_EQ(events.back().kind, EventKind::kGroundTruth);
  EXPECT_EQ(events.back().utime, TumFixture::kT0 + 150000);
}

TEST(Playback, WindowSelectsFramesByTimeAndCanDropStreams) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 6);
  const TumSequence s(fx.folder().string());
  PlaybackWindow w;
  w.start_s = 0.05;     // frames 2.. (66.7 ms)
  w.duration_s = 0.07;  // up to 120 ms: frames 2 and 3
  w.imu = false;
  const auto events = playback_schedule(s, w);
  std::vector<size_t> frames;
  std::vector<int64_t> poses;
  for (const auto& e : events) {
    ASSERT_NE(e.kind, EventKind::kImu);
    if (e.kind == EventKind::kFrame) frames.push_back(e.index);
    if (e.kind == EventKind::kGroundTruth) poses.push_back(e.utime - TumFixture::kT0);
  }
  EXPECT_EQ(frames, (std::vector<size_t>{2, 3}));
  // The poses (every 10 ms) from 50 ms before frame 2 (66.7 ms) to 50 ms after frame 3 (100 ms),
  // bracketed: none inside left out, none beyond the one on each side.
  EXPECT_EQ(poses, (std::vector<int64_t>{10000, 20000, 30000, 40000, 50000, 60000, 70000, 80000, 90000, 100000,
                                         110000, 120000, 130000, 140000, 150000}));
  w.start_s = 10.0;
  EXPECT_TRUE(playback_schedule(s, w).empty());
  w.start_s = -1.0;
  EXPECT_THROW(playback_schedule(s, w), std::invalid_argument);
  w.start_s = 0.0;
  w.duration_s = std::nan("");
  EXPECT_THROW(playback_schedule(s, w), std::invalid_argument);
}

TEST(Player, MessagesCarryTheSequenceAndTheBodyFrameAcceleration) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 3);
  const TumSequence s(fx.folder().string());
  const auto events = playback_schedule(s, {});
  std::vector<Published> out;
  PlayerOptions o;
  o.rate = 0.0;
  const PlayerStats stats = play(s, events, o, collect(out));
  ASSERT_EQ(out.size(), events.size());
  EXPECT_EQ(stats.frames, 3);
  EXPECT_EQ(stats.passes, 1);

  int64_t imu_seq = 0;
  int frame = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    const Published& p = out[i];
    ASSERT_EQ(p.utime, events[i].utime);
    if (p.channel == channel::kCameraRgbd) {
      const auto m = transport::decode_message<kestrel::rgbd_frame_t>(p.bytes.data(), p.bytes.size(), p.channel);
      const RgbdFrame f = transport::decode_rgbd(m, "test");
      EXPECT_EQ(f.seq, frame);
      EXPECT_EQ(f.utime, TumFixture::rgb_utime(frame));
      EXPECT_EQ(f.depth_utime, TumFixture::depth_utime(frame));
      EXPECT_EQ(f.camera.fx, 517.3);
      EXPECT_EQ(f.rgb.at<cv::Vec3b>(7, 9), TumFixture::rgb_at(frame, 7, 9));
      EXPECT_EQ(f.depth_mm.at<uint16_t>(7, 9), (TumFixture::depth_raw_at(frame, 7, 9) + 2) / 5);
      ++frame;
    } else if (p.channel == channel::kImu) {
      const auto m = transport::decode_message<kestrel::imu_t>(p.bytes.data(), p.bytes.size(), p.channel);
      EXPECT_EQ(m.seq, imu_seq++);
      EXPECT_EQ(m.fields, kestrel::imu_t::HAS_ACCEL);
      const auto& a = s.accelerometer()[events[i].index].accel_kinect;
      // Kinect axes (x left, y up, z forward) -> camera optical frame (x right, y down).
      EXPECT_EQ(m.linear_acceleration[0], -a.x());
      EXPECT_EQ(m.linear_acceleration[1], -a.y());
      EXPECT_EQ(m.linear_acceleration[2], a.z());
      EXPECT_EQ(m.angular_velocity[0], 0.0);
    } else {
      ASSERT_EQ(p.channel, channel::kGroundTruth);
      const auto m = transport::decode_message<kestrel::ground_truth_t>(p.bytes.data(), p.bytes.size(), p.channel);
      EXPECT_EQ(m.frame, kestrel::ground_truth_t::FRAME_CAMERA);
      EXPECT_EQ(m.fields, 0);
      const auto T = transport::from_message(m.T_world_frame, "gt");
      EXPECT_TRUE(T.isApprox(*s.ground_truth().at(m.utime, 0), 1e-9));
    }
  }
  EXPECT_EQ(frame, 3);

  out.clear();
  o.raw_accel_axes = true;
  play(s, events, o, collect(out));
  for (size_t i = 0; i < out.size(); ++i) {
    if (out[i].channel != channel::kImu) continue;
    const auto m = transport::decode_message<kestrel::imu_t>(out[i].bytes.data(), out[i].bytes.size(), "IMU");
    EXPECT_EQ(m.linear_acceleration[0], s.accelerometer()[events[i].index].accel_kinect.x());
  }
}

TEST(Player, LoopingKeepsTimeAndSequenceNumbersIncreasing) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 2);
  const TumSequence s(fx.folder().string());
  PlaybackWindow w;
  w.imu = false;
  const auto events = playback_schedule(s, w);
  std::vector<Published> out;
  PlayerOptions o;
  o.rate = 1000.0;  // paced, but fast: 33 ms of sensor time per 33 us
  o.loop = true;
  o.encoding.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  PlayerSink sink = collect(out);
  sink.stopping = [&out, n = events.size()] { return out.size() >= 3 * n; };
  const PlayerStats stats = play(s, events, o, sink);
  EXPECT_TRUE(stats.stopped);
  EXPECT_EQ(stats.passes, 3);
  ASSERT_EQ(out.size(), 3 * events.size());
  const int64_t period = loop_period_us(s, events);
  // The span (from the pose 50 ms before t0 to the one at or after 50 ms past the last frame,
  // at 90 ms) and one frame interval.
  EXPECT_EQ(period, 140000 + TumFixture::kPeriod);
  std::vector<int64_t> seqs;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].utime, events[i % events.size()].utime + static_cast<int64_t>(i / events.size()) * period);
    if (i > 0) {
      EXPECT_GE(out[i].utime, out[i - 1].utime);
    }
    if (out[i].channel == channel::kCameraRgbd) {
      const auto m = transport::decode_message<kestrel::rgbd_frame_t>(out[i].bytes.data(), out[i].bytes.size(), "c");
      EXPECT_EQ(m.rgb_encoding, kestrel::rgbd_frame_t::RGB_JPEG);
      EXPECT_EQ(m.depth_utime - m.utime, TumFixture::kDepthDelay);
      seqs.push_back(m.seq);
    }
  }
  EXPECT_EQ(seqs, (std::vector<int64_t>{0, 1, 2, 3, 4, 5}));  // + 2 RGB images per pass
}

TEST(Player, RejectsUnpacedLoopsAndBadRates) {
  test::TempDir dir;
  const TumFixture fx(dir.path(), 1);
  const TumSequence s(fx.folder().string());
  const auto events = playback_schedule(s, {});
  std::vector<Published> out;
  PlayerOptions o;
  o.rate = 0.0;
  o.loop = true;
  EXPECT_THROW(play(s, events, o, collect(out)), std::invalid_argument);
  o.loop = false;
  o.rate = -1.0;
  EXPECT_THROW(play(s, events, o, collect(out)), std::invalid_argument);
  EXPECT_TRUE(out.empty());
}

}  // namespace
}  // namespace kestrel::tum
