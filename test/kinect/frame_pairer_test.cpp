// Pairing the Kinect's RGB and depth streams by device time (frame_pairer.h).

#include <gtest/gtest.h>

#include "drivers/kinect/frame_pairer.h"

namespace kestrel::kinect {
namespace {

// Frames carry their own device time in the image so a test can tell which one came out.
StreamFrame frame(int64_t device_us, int64_t host_utime = 0) {
  return {device_us, host_utime, cv::Mat(1, 1, CV_64FC1, cv::Scalar(static_cast<double>(device_us)))};
}

std::vector<std::pair<int64_t, int64_t>> drain(FramePairer& p) {
  std::vector<std::pair<int64_t, int64_t>> out;
  while (auto f = p.next()) out.emplace_back(f->rgb.device_us, f->depth.device_us);
  return out;
}

using Pairs = std::vector<std::pair<int64_t, int64_t>>;

TEST(FramePairer, DepthBeforeRgbPairsWhenTheNextDepthShowsItIsNearest) {
  FramePairer p;
  p.add_depth(frame(1000));
  p.add_rgb(frame(15000));  // depth 14 ms earlier; a later depth might be nearer: wait
  EXPECT_TRUE(drain(p).empty());
  p.add_depth(frame(34333));  // 19.3 ms later: the earlier one wins
  EXPECT_EQ(drain(p), (Pairs{{15000, 1000}}));
  p.add_rgb(frame(48333));
  p.add_depth(frame(67666));
  EXPECT_EQ(drain(p), (Pairs{{48333, 34333}}));
  EXPECT_EQ(p.stats().paired, 2);
  EXPECT_EQ(p.stats().unused_depth, 0);
}

TEST(FramePairer, DepthAfterRgbPairsAsSoonAsItArrives) {
  FramePairer p;
  p.add_rgb(frame(0));
  EXPECT_TRUE(drain(p).empty());
  p.add_depth(frame(36));  // fr1_rpy: depth 36 us after RGB
  EXPECT_EQ(drain(p), (Pairs{{0, 36}}));
  // A depth frame already at or after the RGB time decides it on arrival of the RGB frame.
  p.add_depth(frame(33400));
  p.add_rgb(frame(33333));
  EXPECT_EQ(drain(p), (Pairs{{33333, 33400}}));
}

TEST(FramePairer, TheNearerOfTheTwoNeighboursWins) {
  FramePairer p;
  p.add_depth(frame(0));
  p.add_rgb(frame(17000));   // 17 ms after one depth frame ...
  p.add_depth(frame(33333));  // ... 16.3 ms before the next: the later one is nearer
  EXPECT_EQ(drain(p), (Pairs{{17000, 33333}}));
  EXPECT_EQ(p.stats().unused_depth, 1);  // the depth at 0 can serve no later RGB frame
}

// fr1_xyz around 1305031105.66 s (us after .5): the RGB frame at .643273 takes the depth at
// .659104 (15.8 ms, against 16.1 ms for .627128), and so does the one at .675166, whose other
// neighbour is 23 ms away: one depth frame serves two RGB frames, none is lost.
TEST(FramePairer, ADepthFrameServesTwoRgbFramesWhenNearestToBoth) {
  FramePairer p;
  p.add_depth(frame(127128));
  p.add_rgb(frame(143273));
  p.add_depth(frame(159104));
  p.add_rgb(frame(175166));
  p.add_depth(frame(198235));
  p.add_rgb(frame(211309));
  p.flush();
  EXPECT_EQ(drain(p), (Pairs{{143273, 159104}, {175166, 159104}, {211309, 198235}}));
  EXPECT_EQ(p.stats().paired, 3);
  EXPECT_EQ(p.stats().shared_depth, 1);
  EXPECT_EQ(p.stats().unused_depth, 1);  // the one at .627128
  EXPECT_EQ(p.stats().unpaired_rgb, 0);
}

TEST(FramePairer, RgbWithoutDepthWithinTheLimitIsCountedNotPaired) {
  FramePairer p;
  p.add_depth(frame(0));
  p.add_rgb(frame(25000));  // 25 ms > 20 ms
  p.add_depth(frame(50000));  // also 25 ms
  EXPECT_TRUE(drain(p).empty());
  EXPECT_EQ(p.stats().unpaired_rgb, 1);
  // The depth at 50 ms can still pair with the next RGB frame.
  p.add_rgb(frame(58000));
  p.add_depth(frame(83000));
  EXPECT_EQ(drain(p), (Pairs{{58000, 50000}}));
  EXPECT_EQ(p.stats().unused_depth, 1);  // the one at 0
}

TEST(FramePairer, WaitEndsOnTheHostClockOrAtTheEnd) {
  PairerOptions o;
  o.wait_us = 40000;
  FramePairer p(o);
  p.add_depth(frame(0, 1000000));
  p.add_rgb(frame(10000, 1010000));
  p.poll(1049999);  // 39.999 ms of waiting
  EXPECT_TRUE(drain(p).empty());
  p.poll(1050000);  // the next depth frame is lost: decide with what there is
  EXPECT_EQ(drain(p), (Pairs{{10000, 0}}));

  FramePairer q;
  q.add_depth(frame(0));
  q.add_rgb(frame(5000));
  q.add_depth(frame(-1));  // out of order: rejected
  EXPECT_EQ(q.stats().out_of_order, 1);
  q.flush();
  EXPECT_EQ(drain(q), (Pairs{{5000, 0}}));
}

TEST(FramePairer, GapsCountDroppedFramesAndTimeMustAdvance) {
  FramePairer p;
  for (int64_t t : {0, 33333, 100000, 133333, 266667}) p.add_rgb(frame(t));  // 1 then 3 missing
  for (int64_t t : {1000, 34333, 67666, 101000}) p.add_depth(frame(t));
  EXPECT_EQ(p.stats().dropped_rgb, 4);
  EXPECT_EQ(p.stats().dropped_depth, 0);
  p.add_rgb(frame(266667));  // not after the previous RGB frame
  EXPECT_EQ(p.stats().out_of_order, 1);
  EXPECT_EQ(p.stats().rgb_frames, 5);
  EXPECT_THROW(FramePairer(PairerOptions{-1, 0, 1}), std::invalid_argument);
}

TEST(DeviceClock, UnwrapsThe32BitSixtyMegahertzCounter) {
  DeviceClock c;
  EXPECT_EQ(c.to_microseconds(4294967295u - 59u), (4294967295LL - 59) / 60);
  // One frame (2,000,000 ticks = 33.333 ms) later, across the wrap.
  EXPECT_EQ(c.to_microseconds(2000000u - 60u), (4294967296LL + 2000000 - 60) / 60);
  // A stamp of the other stream a little earlier goes back, not forward by 71 s.
  EXPECT_EQ(c.to_microseconds(4294967295u - 119u), (4294967295LL - 119) / 60);
}

}  // namespace
}  // namespace kestrel::kinect
