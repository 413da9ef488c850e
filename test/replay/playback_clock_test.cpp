// PlaybackClock: when a controlled timed replay publishes each event, worked by hand.

#include "tools/replay/playback_clock.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace kestrel::replay {
namespace {

TEST(PlaybackClock, PlaysLogTimeAtItsSpeedFromTheStart) {
  const PlaybackClock clock(2.0, 10'000'000, 100.0);  // log 10 s at wall 100 s, twice as fast
  EXPECT_DOUBLE_EQ(clock.due_s(10'000'000), 100.0);
  EXPECT_DOUBLE_EQ(clock.due_s(14'000'000), 102.0);  // 4 s of log in 2 s
  EXPECT_DOUBLE_EQ(clock.due_s(9'000'000), 99.5);     // behind the position: already due
  EXPECT_EQ(clock.position_us(101.5), 13'000'000);
  EXPECT_EQ(clock.position_us(99.0), 10'000'000);    // before the start: at the start
}

TEST(PlaybackClock, PauseHoldsThePositionAndPlayResumesFromIt) {
  PlaybackClock clock(1.0, 0, 0.0);
  clock.pause(3.0);  // at log 3 s
  EXPECT_TRUE(clock.paused());
  EXPECT_TRUE(std::isinf(clock.due_s(3'500'000)));
  EXPECT_EQ(clock.position_us(50.0), 3'000'000);
  clock.pause(60.0);  // a second pause changes nothing
  EXPECT_EQ(clock.position_us(70.0), 3'000'000);
  clock.play(100.0);  // 97 s later: resumes at log 3 s
  EXPECT_FALSE(clock.paused());
  EXPECT_DOUBLE_EQ(clock.due_s(3'500'000), 100.5);
  clock.play(200.0);  // playing already: no re-anchor
  EXPECT_DOUBLE_EQ(clock.due_s(3'500'000), 100.5);
}

TEST(PlaybackClock, ANewSpeedTakesEffectFromThePosition) {
  PlaybackClock clock(1.0, 0, 0.0);
  clock.set_speed(4.0, 2.0);  // at log 2 s
  EXPECT_DOUBLE_EQ(clock.due_s(6'000'000), 3.0);  // 4 s of log in 1 s
  EXPECT_EQ(clock.position_us(2.5), 4'000'000);
  clock.pause(2.5);
  clock.set_speed(0.5, 10.0);  // paused: stays paused, at log 4 s
  EXPECT_TRUE(clock.paused());
  EXPECT_EQ(clock.position_us(20.0), 4'000'000);
  clock.play(20.0);
  EXPECT_DOUBLE_EQ(clock.due_s(5'000'000), 22.0);  // 1 s of log in 2 s
}

TEST(PlaybackClock, SeekMovesThePositionEitherWayAndKeepsPausedOrPlaying) {
  PlaybackClock clock(1.0, 0, 0.0);
  clock.seek(30'000'000, 5.0);
  EXPECT_EQ(clock.position_us(6.0), 31'000'000);
  clock.seek(1'000'000, 6.0);  // back
  EXPECT_DOUBLE_EQ(clock.due_s(2'000'000), 7.0);
  clock.pause(6.0);
  clock.seek(8'000'000, 9.0);
  EXPECT_TRUE(clock.paused());
  EXPECT_EQ(clock.position_us(12.0), 8'000'000);
}

TEST(PlaybackClock, ASkippedGapMakesTheEventAfterItDueSooner) {
  PlaybackClock clock(1.0, 0, 0.0);
  clock.skip(3'595'000'000);  // an hour-long gap played as 5 s
  EXPECT_DOUBLE_EQ(clock.due_s(3'600'000'000), 5.0);
}

TEST(PlaybackClock, ASpeedThatIsNotPositiveAndFiniteIsRefused) {
  EXPECT_THROW(PlaybackClock(0.0, 0, 0.0), std::invalid_argument);
  EXPECT_THROW(PlaybackClock(-1.0, 0, 0.0), std::invalid_argument);
  PlaybackClock clock(1.0, 0, 0.0);
  EXPECT_THROW(clock.set_speed(std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(clock.set_speed(std::numeric_limits<double>::infinity(), 1.0), std::invalid_argument);
  EXPECT_DOUBLE_EQ(clock.speed(), 1.0);  // unchanged
  EXPECT_EQ(clock.position_us(1.0), 1'000'000);
}

TEST(PlaybackClock, StampsFarApartDoNotOverflow) {
  PlaybackClock clock(1.0, INT64_MIN + 1, 0.0);
  EXPECT_GT(clock.due_s(INT64_MAX), 1e12);
  EXPECT_TRUE(std::isfinite(clock.due_s(INT64_MAX)));
  clock.seek(INT64_MAX - 10, 0.0);
  EXPECT_EQ(clock.position_us(1e6), INT64_MAX);  // 1e12 us ahead of near the end: the end
  clock.skip(int64_t{1} << 62);
  EXPECT_EQ(clock.position_us(0.0), INT64_MAX);
}

}  // namespace
}  // namespace kestrel::replay
