// The health board: heartbeats matched by pid, silence noticed, endings kept.

#include "tools/launch/health.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace kestrel::launch {
namespace {

using Clock = HealthBoard::Clock;
using std::chrono::milliseconds;

process_status_t beat(const std::string& name, int32_t pid, int8_t state, int64_t in = 0) {
  process_status_t s{};
  s.name = name;
  s.pid = pid;
  s.state = state;
  s.messages_in = in;
  return s;
}

TEST(HealthBoard, FollowsEachProcessThroughItsLife) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("vo", 100, t0);
  board.started("estimator", 101, t0);
  EXPECT_EQ(board.rows(t0)[0].state, "starting");
  EXPECT_FALSE(board.all_running(t0));

  // Matched by pid, whatever name the process gives itself.
  board.heartbeat(beat("odometry", 100, process_status_t::STATE_RUNNING, 42), t0 + milliseconds(500));
  board.heartbeat(beat("estimator", 101, process_status_t::STATE_DEGRADED), t0 + milliseconds(500));
  auto rows = board.rows(t0 + milliseconds(600));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].state, "RUNNING");
  EXPECT_EQ(rows[0].last->messages_in, 42);
  EXPECT_EQ(rows[1].state, "DEGRADED");
  EXPECT_FALSE(board.all_running(t0 + milliseconds(600)));
  board.heartbeat(beat("estimator", 101, process_status_t::STATE_RUNNING), t0 + milliseconds(900));
  EXPECT_TRUE(board.all_running(t0 + milliseconds(1000)));

  // Silence: older than 3 s.
  rows = board.rows(t0 + milliseconds(4000));
  EXPECT_EQ(rows[0].state, "silent 3.5 s");
  EXPECT_FALSE(rows[0].healthy);

  board.ended("vo", "killed by SIGSEGV", t0 + milliseconds(3000));
  EXPECT_EQ(board.rows(t0 + milliseconds(4000))[0].state, "ended: killed by SIGSEGV");
  // A restart forgets the old pid's heartbeats.
  board.started("vo", 200, t0 + milliseconds(5000));
  board.heartbeat(beat("vo", 100, process_status_t::STATE_RUNNING), t0 + milliseconds(5100));
  rows = board.rows(t0 + milliseconds(5200));
  EXPECT_EQ(rows[0].state, "starting");
  EXPECT_EQ(rows.back().name, "vo (not launched here)");  // the stale pid, shown apart
}

// What a process sends as it stops (its STOPPING heartbeat, its counts) often arrives after
// the launch has reaped it: it is still that process's, not a stranger's.
TEST(HealthBoard, WhatAProcessSaysAsItStopsIsItsOwnAfterItEnded) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("slam", 300, t0);
  board.started("source", 301, t0);
  board.heartbeat(beat("slam", 300, process_status_t::STATE_RUNNING), t0 + milliseconds(100));
  board.ended("slam", "exited with status 0", t0 + milliseconds(200));
  board.ended("source", "exited with status 0", t0 + milliseconds(200));
  board.heartbeat(beat("slam", 300, process_status_t::STATE_STOPPING), t0 + milliseconds(250));
  // The source never said its name before it ended: its launch name is not its own.
  board.heartbeat(beat("ros-bridge", 301, process_status_t::STATE_STOPPING), t0 + milliseconds(250));
  rejection_counts_t counts{};
  counts.name = "slam";
  counts.pid = 300;
  counts.num_reasons = 0;
  board.rejections(counts);
  const auto rows = board.rows(t0 + milliseconds(300));
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].name, "slam");
  EXPECT_EQ(rows[0].state, "ended: exited with status 0");
  EXPECT_EQ(rows[1].name, "source");
  EXPECT_EQ(rows[2].name, "ros-bridge (not launched here)");
}

// A heartbeat's name and message reach the terminal escaped, whatever bytes they hold (found
// by fuzzing: a backspace and invalid UTF-8 in a message went to the table raw).
TEST(HealthBoard, TheTableEscapesBytesThatDoNotPrint) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("vo", 100, t0);
  process_status_t s = beat("v\x1b[2Jo", 100, process_status_t::STATE_DEGRADED);
  s.message = std::string("rejecting IMU: be\x08yond s\xea\xa5 range\nnext");
  board.heartbeat(s, t0);
  process_status_t stranger = beat("x\ty", 7, process_status_t::STATE_RUNNING);
  board.heartbeat(stranger, t0);
  const std::string table = board.table(t0);
  for (const char c : table) {
    const auto u = static_cast<unsigned char>(c);
    EXPECT_FALSE((u < 0x20 && c != '\n') || u >= 0x7f) << "byte " << int(u) << " in:\n" << table;
  }
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 3) << table;  // header and two rows
  EXPECT_NE(table.find("be\\x08yond s\\xEA\\xA5 range\\nnext"), std::string::npos) << table;
}

rejection_reason_t reason(const std::string& channel, const std::string& kind, int64_t count, const std::string& last) {
  rejection_reason_t r;
  r.channel = channel;
  r.reason = kind;
  r.count = count;
  r.last = last;
  return r;
}

// What each process refused, under its launch name (matched by pid), each reason with its
// count and the latest one in full, escaped; nothing refused, no table; a restart starts over.
TEST(HealthBoard, TheRejectionsTableNamesEachProcessChannelAndReason) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("estimator", 101, t0);
  board.started("vo", 102, t0);
  EXPECT_EQ(board.rejections_table(), "");
  rejection_counts_t c{};
  c.name = "estimator";
  c.pid = 101;
  c.rejected = 4;
  c.reasons = {reason("IMU", "accelerometer # m/s^# beyond # m/s^#", 3, "accelerometer 700.5 m/s^2 beyond 160 m/s^2"),
               reason("VO_UPDATE", "reference keyframe # is \x1b unknown", 1, "reference keyframe 12 is \x1b unknown")};
  c.num_reasons = 2;
  board.rejections(c);
  const std::string table = board.rejections_table();
  EXPECT_NE(table.find("rejected by"), std::string::npos) << table;
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 5) << table;  // header, two lines per reason
  EXPECT_NE(table.find("estimator        IMU                       3  accelerometer # m/s^# beyond # m/s^#"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("last: accelerometer 700.5 m/s^2 beyond 160 m/s^2"), std::string::npos) << table;
  EXPECT_EQ(table.find("vo "), std::string::npos) << "vo refused nothing:\n" << table;
  for (const char ch : table) {
    const auto u = static_cast<unsigned char>(ch);
    EXPECT_FALSE((u < 0x20 && ch != '\n') || u >= 0x7f) << "byte " << int(u) << " in:\n" << table;
  }
  board.ended("estimator", "killed by SIGKILL", t0 + milliseconds(10));
  board.started("estimator", 201, t0 + milliseconds(20));
  EXPECT_EQ(board.rejections_table(), "") << "the restarted estimator has refused nothing yet";
}

TEST(HealthBoard, ASourceWithoutHeartbeatsIsRunningUntilItEnds) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("vo", 1, t0);
  board.started("source", 2, t0, /*heartbeats=*/false);
  board.heartbeat(beat("vo", 1, process_status_t::STATE_RUNNING), t0 + milliseconds(100));
  EXPECT_TRUE(board.all_running(t0 + milliseconds(200)));
  EXPECT_EQ(board.rows(t0 + milliseconds(5000))[1].state, "running");
  board.ended("source", "exited with status 0", t0 + milliseconds(4000));
  EXPECT_EQ(board.rows(t0 + milliseconds(5000))[1].state, "ended: exited with status 0");
}

TEST(HealthBoard, CpuIsAShareOfOneCoreOverTheProcesssLife) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("vo", 1, t0);
  board.started("mapper", 2, t0);
  EXPECT_FALSE(board.rows(t0 + milliseconds(100))[0].cpu_percent.has_value());  // not measured yet
  board.cpu("vo", 0.5);  // 0.5 s of CPU in its first 2 s: 25 %
  EXPECT_NEAR(*board.rows(t0 + milliseconds(2000))[0].cpu_percent, 25.0, 1e-9);
  // Ended after 4 s with 3 s of CPU: 75 %, however long after its end the table is drawn.
  board.ended("vo", "exited with status 0", t0 + milliseconds(4000), 3.0);
  board.cpu("vo", 9.0);  // a stale reading after its end changes nothing
  EXPECT_NEAR(*board.rows(t0 + milliseconds(9000))[0].cpu_percent, 75.0, 1e-9);
  board.ended("mapper", "exited with status 0", t0 + milliseconds(1000));  // CPU unknown
  EXPECT_FALSE(board.rows(t0 + milliseconds(9000))[1].cpu_percent.has_value());
  const std::string table = board.table(t0 + milliseconds(9000));
  EXPECT_NE(table.find("cpu %"), std::string::npos) << table;
  EXPECT_NE(table.find("   3.00   75.0  ended: exited with status 0"), std::string::npos) << table;
}

TEST(HealthBoard, AProcessThatNeverBeatsIsNamed) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("mapper", 7, t0);
  EXPECT_EQ(board.rows(t0 + milliseconds(3500))[0].state, "no heartbeat");
  const std::string table = board.table(t0 + milliseconds(3500));
  EXPECT_NE(table.find("mapper"), std::string::npos);
  EXPECT_NE(table.find("no heartbeat"), std::string::npos);
}

// The launcher starts its source once this is empty: any heartbeat counts (a process waiting
// for data says STARTING), a source that never beats and a process that ended do not wait.
TEST(HealthBoard, NotYetHeardNamesTheProcessesStillToSendTheirFirstHeartbeat) {
  HealthBoard board(3.0);
  const auto t0 = Clock::now();
  board.started("vo", 1, t0);
  board.started("estimator", 2, t0);
  board.started("mapper", 3, t0);
  board.started("source", 4, t0, /*heartbeats=*/false);
  EXPECT_EQ(board.not_yet_heard(), (std::vector<std::string>{"vo", "estimator", "mapper"}));
  board.heartbeat(beat("estimator", 2, process_status_t::STATE_STARTING), t0 + milliseconds(100));
  board.ended("mapper", "exited with status 1", t0 + milliseconds(200));
  EXPECT_EQ(board.not_yet_heard(), std::vector<std::string>{"vo"});
  board.heartbeat(beat("vo", 1, process_status_t::STATE_DEGRADED), t0 + milliseconds(300));
  EXPECT_TRUE(board.not_yet_heard().empty());
  board.started("vo", 5, t0 + milliseconds(400));  // restarted: its new pid has not beaten
  EXPECT_EQ(board.not_yet_heard(), std::vector<std::string>{"vo"});
}

}  // namespace
}  // namespace kestrel::launch
