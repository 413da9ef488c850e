// The supervisor with real child processes (plain shell commands): exit statuses, signals,
// restarts and a stop that also ends a child that ignores SIGTERM.

#include "tools/launch/supervisor.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "test/support/test_support.h"

namespace kestrel::launch {
namespace {

using test::TempDir;
using Clock = Supervisor::Clock;

ProcessSpec shell(const std::string& name, const std::string& script) {
  return {name, {"/bin/sh", "-c", script}, "onboard"};
}

// Polls until `n` events of `kind` arrived or 10 s passed.
std::vector<ChildEvent> poll_until(Supervisor& s, ChildEvent::Kind kind, size_t n) {
  std::vector<ChildEvent> seen;
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  size_t count = 0;
  while (count < n && Clock::now() < deadline) {
    for (const auto& e : s.poll()) {
      seen.push_back(e);
      count += e.kind == kind;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return seen;
}

TEST(DescribeWaitStatus, ExitCodesAndSignals) {
  EXPECT_EQ(describe_wait_status(3 << 8).description, "exited with status 3");
  EXPECT_EQ(describe_wait_status(3 << 8).code, 3);
  EXPECT_EQ(describe_wait_status(SIGSEGV).description, "killed by SIGSEGV");
  EXPECT_EQ(describe_wait_status(SIGSEGV).code, 128 + SIGSEGV);
}

TEST(Supervisor, ReportsHowEachChildEndedAndKeepsItsOutput) {
  TempDir dir;
  SupervisorOptions o;
  o.log_dir = dir / "logs";
  o.environment = {"KESTREL_TEST_VALUE=seen"};
  const ProcessSet set{shell("fails", "echo \"why: $KESTREL_TEST_VALUE\"; exit 3"),
                       shell("crashes", "kill -SEGV $$")};
  Supervisor s(set, {"/bin/sh", "/bin/sh"}, o);
  const auto started = s.start_all();
  ASSERT_EQ(started.size(), 2u);
  EXPECT_EQ(started[0].kind, ChildEvent::kStarted);
  auto events = poll_until(s, ChildEvent::kEnded, 2);
  std::map<std::string, std::string> how;
  for (const auto& e : events)
    if (e.kind == ChildEvent::kEnded) how[e.name] = e.ending.description;
  EXPECT_EQ(how["fails"], "exited with status 3");
  EXPECT_EQ(how["crashes"], "killed by SIGSEGV");
  EXPECT_EQ(s.running(), 0u);
  std::stringstream log;
  log << std::ifstream(o.log_dir / "fails.log").rdbuf();
  EXPECT_EQ(log.str(), "why: seen\n");
}

// The kernel's count of a child's CPU: while it runs (/proc) and when it ends (wait4). A busy
// loop uses CPU, a sleep almost none, whatever else the machine does.
TEST(Supervisor, CountsTheCpuEachChildUsed) {
  TempDir dir;
  SupervisorOptions o;
  o.log_dir = dir / "logs";
  const ProcessSet set{shell("busy", "i=0; while [ $i -lt 400000 ]; do i=$((i+1)); done"),
                       shell("sleeps", "sleep 0.3")};
  Supervisor s(set, {"/bin/sh", "/bin/sh"}, o);
  s.start_all();
  const pid_t busy = s.find("busy")->pid;
  std::optional<double> running_cpu;
  for (int i = 0; i < 200; ++i) {  // nothing reaps it meanwhile: /proc keeps its entry
    if (const auto c = process_cpu_seconds(busy)) running_cpu = c;
    if (running_cpu && *running_cpu > 0.02) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(running_cpu.has_value()) << "no /proc/<pid>/stat for a running child";
  std::map<std::string, double> cpu;
  for (const auto& e : poll_until(s, ChildEvent::kEnded, 2))
    if (e.kind == ChildEvent::kEnded) cpu[e.name] = e.ending.cpu_s;
  ASSERT_EQ(cpu.size(), 2u);
  EXPECT_GT(cpu["busy"], 0.05);
  EXPECT_GE(cpu["busy"], *running_cpu);
  EXPECT_GE(cpu["sleeps"], 0.0);
  EXPECT_LT(cpu["sleeps"], 0.05);
  EXPECT_FALSE(process_cpu_seconds(busy).has_value());  // reaped: gone from /proc
  // This process: what /proc says is what getrusage says, read before and after it, to the
  // clock ticks /proc counts in (four fields, each truncated to 10 ms).
  auto kernel = [] {
    auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
    struct rusage self {}, children {};
    ::getrusage(RUSAGE_SELF, &self);
    ::getrusage(RUSAGE_CHILDREN, &children);
    return seconds(self.ru_utime) + seconds(self.ru_stime) + seconds(children.ru_utime) + seconds(children.ru_stime);
  };
  const double before = kernel();
  const double proc = process_cpu_seconds(::getpid()).value_or(-1.0);
  const double after = kernel();
  EXPECT_GE(proc, before - 0.045);
  EXPECT_LE(proc, after + 0.005);
}

TEST(Supervisor, RestartsADeadChildUpToTheLimit) {
  TempDir dir;
  SupervisorOptions o;
  o.log_dir = dir.path();
  o.restart = true;
  o.restart_delay_s = 0.01;
  o.max_restarts = 2;
  // A restart adds restart_args: here the script's $0 (the first run's is the shell's path).
  ProcessSpec flaky = shell("flaky", "echo \"run $0\" >> " + (dir / "runs").string() + "; exit 1");
  flaky.restart_args = {"again"};
  Supervisor s({flaky}, {"/bin/sh"}, o);
  s.start_all();
  const auto events = poll_until(s, ChildEvent::kGaveUp, 1);
  int ended = 0, restarting = 0, gave_up = 0;
  for (const auto& e : events) {
    ended += e.kind == ChildEvent::kEnded;
    restarting += e.kind == ChildEvent::kRestarting;
    gave_up += e.kind == ChildEvent::kGaveUp;
  }
  EXPECT_EQ(ended, 3);  // the first run and two restarts
  EXPECT_EQ(restarting, 2);
  EXPECT_EQ(gave_up, 1);
  EXPECT_EQ(s.children()[0].restarts, 2);
  std::ifstream runs(dir / "runs");
  std::vector<std::string> lines;
  for (std::string l; std::getline(runs, l);) lines.push_back(l);
  EXPECT_EQ(lines, (std::vector<std::string>{"run /bin/sh", "run again", "run again"}));
}

TEST(Supervisor, StopEndsEveryChildEvenOneThatIgnoresSigterm) {
  TempDir dir;
  SupervisorOptions o;
  o.log_dir = dir.path();
  o.stop_timeout_s = 0.5;
  const ProcessSet set{shell("polite", "exec sleep 30"),
                       shell("stubborn", "trap '' TERM; echo ready; while :; do sleep 0.05; done")};
  Supervisor s(set, {"/bin/sh", "/bin/sh"}, o);
  s.start_all();
  // Let the stubborn one install its trap before we signal it.
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (Clock::now() < deadline) {
    std::ifstream log(dir / "stubborn.log");
    std::string l;
    if (std::getline(log, l) && l == "ready") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const pid_t stubborn = s.find("stubborn")->pid;
  const auto t0 = Clock::now();
  const auto events = s.stop_all();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 5.0);
  EXPECT_EQ(s.running(), 0u);
  std::map<std::string, std::string> how;
  for (const auto& e : events) how[e.name] = e.ending.description;
  EXPECT_EQ(how["polite"], "killed by SIGTERM");
  EXPECT_EQ(how["stubborn"], "killed by SIGKILL");
  EXPECT_NE(::kill(stubborn, 0), 0) << "the stubborn child still exists";
}

}  // namespace
}  // namespace kestrel::launch
