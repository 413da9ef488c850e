// kestrel-launch end to end, with two rgbd-codec processes as the set (they heartbeat like
// every kestrel process): health from heartbeats, a killed process reported and restarted,
// clean stops, a source that ends the launch (and is never said to restart), children that end
// with a launcher killed by SIGKILL, and bad process-set files or process names.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <map>
#include <regex>
#include <thread>

#include "common/transport/log_file.h"
#include "test/replay/fixtures.h"
#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

class LaunchTool : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a private network namespace here";
    std::ofstream(sets) << "processes:\n"
                           "  - {name: codec-a, command: rgbd-codec --name codec-a --out A, side: onboard}\n"
                           "  - {name: codec-b, command: rgbd-codec --name codec-b --in A --out B, side: offboard}\n";
  }
  std::unique_ptr<Background> launch(std::vector<std::string> extra) {
    std::vector<std::string> argv{tool("launch"), "all", "--sets", sets.string(), "--isolated",
                                  "--status-period", "0.5", "--log-dir", (dir / "logs").string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<Background>(argv, dir.path(), "launch");
  }
  // The pid the launcher reported for the latest start of `name`.
  static pid_t started_pid(const Background& b, const std::string& name) {
    const std::string err = b.err();
    const std::regex re("started " + name + " \\(pid ([0-9]+)\\)");
    pid_t pid = -1;
    for (auto it = std::sregex_iterator(err.begin(), err.end(), re); it != std::sregex_iterator(); ++it)
      pid = std::stoi((*it)[1]);
    return pid;
  }

  TempDir dir;
  std::filesystem::path sets = dir / "sets.yaml";
};

TEST_F(LaunchTool, ShowsHealthReportsAKilledProcessAndRestartsIt) {
  auto l = launch({"--restart"});
  ASSERT_TRUE(l->wait_for_output("all processes running", 20, true)) << l->err();
  ASSERT_TRUE(l->wait_for_output("RUNNING", 10)) << l->out();
  const pid_t first = started_pid(*l, "codec-a");
  ASSERT_GT(first, 0);
  ASSERT_EQ(::kill(first, SIGKILL), 0);
  ASSERT_TRUE(l->wait_for_output("codec-a (pid " + std::to_string(first) + ") killed by SIGKILL", 10, true))
      << l->err();
  ASSERT_TRUE(l->wait_for_output("restarting codec-a", 10, true)) << l->err();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  pid_t second = first;
  while (second == first && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    second = started_pid(*l, "codec-a");
  }
  ASSERT_NE(second, first) << l->err();

  l->signal(SIGTERM);
  const auto code = l->wait_exit(15);
  ASSERT_TRUE(code.has_value()) << "the launcher did not stop";
  // The restart was asked for, so the kill is not a failure; the stop is clean.
  EXPECT_EQ(*code, 0) << l->err();
  EXPECT_NE(l->out().find("ended: exited with status 0"), std::string::npos) << l->out();
  EXPECT_NE(::kill(second, 0), 0) << "codec-a outlived the launcher";
}

// restart_args at the first start only when one side is launched alone (the other may be
// running with its state: process_set.h, joining_a_running_system), seen in the child's
// command line.
TEST_F(LaunchTool, ASideLaunchedAloneStartsItsProcessesAsRestartedOnes) {
  std::ofstream(sets) << "processes:\n"
                         "  - {name: codec-a, command: rgbd-codec --name codec-a --out A, restart_args: --max-rate 5, side: onboard}\n"
                         "  - {name: codec-b, command: rgbd-codec --name codec-b --in A --out B, side: offboard}\n";
  for (const std::string side : {"all", "onboard"}) {
    Background l({tool("launch"), side, "--sets", sets.string(), "--isolated", "--status-period", "0.5", "--log-dir",
                  (dir / ("logs-" + side)).string()},
                 dir.path(), "launch-" + side);
    ASSERT_TRUE(l.wait_for_output("all processes running", 20, true)) << l.err();
    const pid_t a = started_pid(l, "codec-a");
    ASSERT_GT(a, 0) << l.err();
    std::string cmdline = read_file("/proc/" + std::to_string(a) + "/cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    EXPECT_EQ(cmdline.find("--max-rate 5") != std::string::npos, side == "onboard") << side << ": " << cmdline;
    l.signal(SIGTERM);
    ASSERT_TRUE(l.wait_exit(15).has_value()) << "the launcher did not stop";
  }
}

TEST_F(LaunchTool, WithoutRestartADeadProcessIsAFailureAndCtrlCStopsTheRest) {
  auto l = launch({});
  ASSERT_TRUE(l->wait_for_output("all processes running", 20, true)) << l->err();
  const pid_t b = started_pid(*l, "codec-b");
  ASSERT_EQ(::kill(b, SIGKILL), 0);
  ASSERT_TRUE(l->wait_for_output("codec-b (pid " + std::to_string(b) + ") killed by SIGKILL", 10, true));
  const pid_t a = started_pid(*l, "codec-a");
  EXPECT_EQ(::kill(a, 0), 0) << "the peer of a dead process must keep running";
  l->signal(SIGINT);
  const auto code = l->wait_exit(15);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 130);
  EXPECT_NE(::kill(a, 0), 0);
}

// True while `pid` is a process that has not ended. A dead child that its new parent has not
// reaped yet (a zombie, state Z or X in /proc) has ended.
bool alive(pid_t pid) {
  if (::kill(pid, 0) != 0) return false;
  const std::string stat = read_file("/proc/" + std::to_string(pid) + "/stat");
  const size_t paren = stat.rfind(')');
  if (paren == std::string::npos || paren + 2 >= stat.size()) return false;
  const char state = stat[paren + 2];
  return state != 'Z' && state != 'X';
}

TEST_F(LaunchTool, EveryChildEndsWithALauncherKilledBySigkill) {
  // The source too: a plain program that would otherwise sleep for ten minutes.
  auto l = launch({"--source", "/bin/sleep 600"});
  ASSERT_TRUE(l->wait_for_output("all processes running", 20, true)) << l->err();
  std::map<std::string, pid_t> children;
  for (const std::string name : {"codec-a", "codec-b", "source"}) {
    children[name] = started_pid(*l, name);
    ASSERT_GT(children[name], 0) << name << " was not started: " << l->err();
    ASSERT_TRUE(alive(children[name])) << name;
  }
  l->signal(SIGKILL);  // no handler runs: only the kernel can end the children now
  ASSERT_TRUE(l->wait_exit(10).has_value()) << "the launcher survived SIGKILL";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  const auto any_alive = [&] {
    for (const auto& [name, pid] : children)
      if (alive(pid)) return true;
    return false;
  };
  while (any_alive() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  for (const auto& [name, pid] : children) {
    EXPECT_FALSE(alive(pid)) << name << " (pid " << pid << ") outlived its launcher by 5 s";
    if (alive(pid)) ::kill(-pid, SIGKILL);  // not left behind by a failing test
  }
}

TEST_F(LaunchTool, TheLaunchEndsWithItsSource) {
  {
    auto l = launch({"--source", "/bin/sleep 1"});
    const auto code = l->wait_exit(20);
    ASSERT_TRUE(code.has_value());
    EXPECT_EQ(*code, 0) << l->err();
    EXPECT_NE(l->err().find("the source exited with status 0"), std::string::npos) << l->err();
  }
  {
    auto l = launch({"--source", "/bin/false"});
    const auto code = l->wait_exit(20);
    ASSERT_TRUE(code.has_value());
    EXPECT_EQ(*code, 1) << l->err();
  }
}

// A process that refused input: when the launch ends, its table names the process, the
// channel, how many of each kind and the latest in full (PROCESS_REJECTIONS). The source
// replays three undecodable frames, then plays on past a heartbeat period so that the count
// of all three has been sent.
TEST_F(LaunchTool, TheLaunchEndsWithATableOfWhatEachProcessRefused) {
  const std::string log = (dir / "bad.lcmlog").string();
  {
    transport::LogWriter w(log);
    for (int i = 0; i < 3; ++i) w.write("CAMERA_RGBD", 1'000'000 + 100'000 * i, std::vector<uint8_t>(5 + i, 0x42));
    w.write("UNHEARD", 3'500'000, {1});
    w.close();
  }
  auto l = launch({"--source", tool("replay").string() + " " + log + " --realtime"});
  const auto code = l->wait_exit(30);
  ASSERT_TRUE(code.has_value()) << l->err();
  EXPECT_EQ(*code, 0) << l->err();
  const std::string out = l->out();
  const size_t table = out.find("rejected by");
  ASSERT_NE(table, std::string::npos) << out;
  const std::regex row(R"(codec-a +CAMERA_RGBD +3  # bytes are too short for any message)");
  EXPECT_TRUE(std::regex_search(out.substr(table), row)) << out.substr(table);
  EXPECT_NE(out.find("last: 7 bytes are too short for any message", table), std::string::npos) << out.substr(table);
  EXPECT_EQ(out.find("codec-b", table), std::string::npos) << "codec-b refused nothing:\n" << out.substr(table);
}

TEST_F(LaunchTool, ASourceThatEndsIsNeverSaidToRestart) {
  auto l = launch({"--restart", "--source", "/bin/sleep 1"});  // --restart is for the processes
  const auto code = l->wait_exit(20);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0) << l->err();
  EXPECT_NE(l->err().find("the source exited with status 0"), std::string::npos) << l->err();
  EXPECT_EQ(l->err().find("restarting source"), std::string::npos) << l->err();
}

TEST_F(LaunchTool, AProcessNameTheSetsDoNotHoldIsAUsageError) {
  for (const char* option : {"--only", "--without"}) {
    const auto r = run({tool("launch"), "all", "--sets", sets.string(), option, "codec-a,nosuch", "--list"});
    EXPECT_EQ(r.exit_code, 2) << option << ": " << r.err;
    EXPECT_NE(r.err.find("kestrel-launch: error: --only/--without: no process named 'nosuch'"), std::string::npos)
        << r.err;
  }
}

TEST_F(LaunchTool, LocalisingOnlyWithoutAMapIsAUsageError) {
  auto r = run({tool("launch"), "all", "--sets", sets.string(), "--localize-only", "--list"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--localize-only requires --map"), std::string::npos) << r.err;
  r = run({tool("launch"), "all", "--sets", sets.string(), "--map", (dir / "m").string(), "--no-map-update", "--list"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--no-map-update requires --localize-only"), std::string::npos) << r.err;
}

TEST_F(LaunchTool, ListsTheSetWithoutStartingIt) {
  const auto r = run({tool("launch"), "onboard", "--sets", sets.string(), "--list"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("codec-a"), std::string::npos);
  EXPECT_EQ(r.out.find("codec-b"), std::string::npos);
  EXPECT_NE(r.out.find("kestrel-rgbd-codec --name codec-a --out A"), std::string::npos) << r.out;
}

TEST_F(LaunchTool, BadSetsAndUnbuiltToolsAreOneLineErrors) {
  std::ofstream(dir / "bad.yaml") << "processes:\n  - {name: x, command: x, side: sideways}\n";
  auto r = run({tool("launch"), "all", "--sets", (dir / "bad.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("bad.yaml:2: side is onboard or offboard"), std::string::npos) << r.err;

  std::ofstream(dir / "unbuilt.yaml") << "processes:\n  - {name: x, command: no-such-tool, side: onboard}\n";
  r = run({tool("launch"), "all", "--sets", (dir / "unbuilt.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no kestrel-no-such-tool"), std::string::npos) << r.err;

  r = run({tool("launch"), "sideways"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = run({tool("launch"), "all", "--sets", (dir / "absent.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("absent.yaml: no such file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace kestrel::test
