// kestrel-replay --control: a recorded flight under review. The test plays the transport
// bar's part: it pauses, seeks both ways, changes the speed and sends nonsense, and checks on
// the bus what the replay published (PLAYBACK_STATUS, and the log's own IMU events).

#include <gtest/gtest.h>

#include <csignal>
#include <lcm/lcm-cpp.hpp>

#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/playback_command_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

constexpr const char* kImu = "IMU";
constexpr const char* kStatus = "PLAYBACK_STATUS";

// IMU at 10 Hz from log time 10 s to 30 s.
void write_log(const std::filesystem::path& path) {
  transport::LogWriter w(path);
  for (int i = 0; i <= 200; ++i) {
    kestrel::imu_t m{};
    m.utime = 10'000'000 + int64_t{i} * 100'000;
    m.seq = i;
    w.write_message(kImu, m.utime, m);
  }
  w.close();
}

class Bar {
 public:
  Bar() : lcm_(transport::resolve_lcm_url("")) {}
  void send(int8_t command, int64_t seek_utime = 0, double speed = 0.0) {
    kestrel::playback_command_t c{};
    c.request_id = ++id_;
    c.command = command;
    c.seek_utime = seek_utime;
    c.speed = speed;
    lcm_.publish("PLAYBACK_COMMAND", &c);
  }
  int64_t last_id() const { return id_; }

 private:
  lcm::LCM lcm_;
  int64_t id_ = 0;
};

// The IMU utimes received from the `from`-th message on.
std::vector<int64_t> imu_after(const LiveSystem& live, size_t from) {
  std::vector<int64_t> t;
  const auto all = live.messages();
  for (size_t i = from; i < all.size(); ++i)
    if (all[i].channel == kImu)
      t.push_back(transport::decode_message<kestrel::imu_t>(all[i].data.data(), all[i].data.size(), kImu).utime);
  return t;
}

TEST(Playback, PauseSeekAndSpeedFromTheBusAndTheEndWaitsForASeekBack) {
  if (const std::string why = LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  TempDir dir;
  write_log(dir / "flight.lcmlog");
  LiveSystem::Options options;
  options.channels = {kImu, kStatus};
  LiveSystem live(dir.path(), options);
  Bar bar;
  using S = kestrel::playback_status_t;
  using C = kestrel::playback_command_t;
  const auto status = [&](const std::function<bool(const S&)>& accept, const std::string& what, size_t from = 0) {
    return live.wait_for<S>(kStatus, accept, 10.0, what, from);
  };
  live.start("replay", {tool("replay").string(), (dir / "flight.lcmlog").string(), "--control"});
  const auto first = status([](const S& s) { return s.utime >= 10'300'000; }, "playing at the log's pace");
  ASSERT_TRUE(first.has_value()) << live.output("replay");
  EXPECT_EQ(first->start_utime, 10'000'000);
  EXPECT_EQ(first->end_utime, 30'000'000);
  EXPECT_EQ(first->log_name, "flight.lcmlog");
  EXPECT_FALSE(first->paused);
  EXPECT_DOUBLE_EQ(first->speed, 1.0);

  // Pause: the position stands and nothing is published while three statuses come.
  bar.send(C::COMMAND_PAUSE);
  const auto paused = status([&](const S& s) { return s.last_request_id == bar.last_id(); }, "the pause");
  ASSERT_TRUE(paused.has_value());
  EXPECT_TRUE(paused->paused);
  const size_t at_pause = live.received();
  int statuses = 0;
  ASSERT_TRUE(status([&](const S&) { return ++statuses == 3; }, "three statuses while paused", at_pause));
  EXPECT_TRUE(imu_after(live, at_pause).empty()) << "published while paused";
  // A speed that is no speed is ignored; the position has not moved.
  bar.send(C::COMMAND_SPEED, 0, -2.0);
  const auto refused = status([&](const S& s) { return s.last_request_id == bar.last_id(); }, "a negative speed");
  ASSERT_TRUE(refused.has_value());
  EXPECT_DOUBLE_EQ(refused->speed, 1.0);
  EXPECT_EQ(refused->utime, paused->utime);

  // Seek ahead while paused: the last event before the new position comes at once, the
  // replay stays paused; play goes on from there.
  const size_t before_seek = live.received();
  bar.send(C::COMMAND_SEEK, 25'000'000);
  const auto sought = status([&](const S& s) { return s.seeks == 1; }, "the seek");
  ASSERT_TRUE(sought.has_value());
  EXPECT_TRUE(sought->paused);
  EXPECT_EQ(sought->utime, 25'000'000);
  bar.send(C::COMMAND_PLAY);
  bar.send(C::COMMAND_SPEED, 0, 10.0);
  const auto ended = status([](const S& s) { return s.at_end; }, "the end, at speed 10");
  ASSERT_TRUE(ended.has_value()) << live.output("replay");
  EXPECT_TRUE(ended->paused);
  EXPECT_DOUBLE_EQ(ended->speed, 10.0);
  const std::vector<int64_t> after_seek = imu_after(live, before_seek);
  ASSERT_EQ(after_seek.size(), 52u);  // 24.9 s (the moment's last), then 25.0 .. 30.0 s
  EXPECT_EQ(after_seek.front(), 24'900'000);
  for (size_t i = 1; i < after_seek.size(); ++i) EXPECT_EQ(after_seek[i], 25'000'000 + int64_t(i - 1) * 100'000);

  // At the end the replay waits; a seek back plays again.
  EXPECT_FALSE(live.wait_exit("replay", 0.3).has_value()) << "the replay ended at the end of the log";
  const size_t at_end = live.received();
  bar.send(C::COMMAND_SEEK, 12'000'000);
  ASSERT_TRUE(live.wait_for<kestrel::imu_t>(
      kImu, [](const kestrel::imu_t& m) { return m.utime >= 12'500'000; }, 10.0, "the log played again from 12 s",
      at_end));
  const std::vector<int64_t> again = imu_after(live, at_end);
  ASSERT_GE(again.size(), 2u);
  EXPECT_EQ(again[0], 11'900'000);
  EXPECT_EQ(again[1], 12'000'000);
  EXPECT_EQ(live.stop("replay", SIGINT), 130);
}

}  // namespace
}  // namespace kestrel::test
