// kestrel-sim as a user runs it: a TUM export that kestrel-eval scores as exact against its
// own ground truth, byte-identical logs for a seed, bad input reported with exit code 3 and
// a world or flight there is not with exit code 2.

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <cmath>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/vehicle_command_t.hpp"
#include "test/support/live_system.h"
#include "test/support/test_support.h"

namespace {

namespace fs = std::filesystem;
using kestrel::test::run;
using kestrel::test::TempDir;
using kestrel::test::tool;

// The stock lcm-logger and lcm-logplayer in a script take kestrel's URL from the environment.
std::string lcm_url_export() {
  return "export LCM_DEFAULT_URL=" + kestrel::test::quoted(kestrel::transport::kDefaultLcmUrl) + " && ";
}

int data_lines(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') ++n;
  return n;
}

// The whole 20 s of flight and of 200 Hz ground truth and IMU, but frames at 3 Hz: the
// export, its time stamps and the evaluation are the same code at any frame rate, and
// rendering and PNG-writing 601 frames cost most of a minute of CPU.
TEST(SimToolTest, TumExportOfTwentySecondsScoresZeroAgainstItsOwnGroundTruth) {
  TempDir dir;
  const fs::path tum = dir / "room";
  const auto sim = run({tool("sim").string(), "--world", "room", "--flight", "loop", "--duration", "20",
                        "--camera-rate", "3", "--tum", tum.string(), "-q"},
                       550.0);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_EQ(data_lines(tum / "rgb.txt"), 61);  // 0 .. 20 s at 3 Hz
  EXPECT_EQ(data_lines(tum / "depth.txt"), 61);
  EXPECT_EQ(data_lines(tum / "imu.txt"), 4001);  // 0 .. 20 s at 200 Hz
  EXPECT_EQ(data_lines(tum / "accelerometer.txt"), 4001);
  EXPECT_EQ(std::distance(fs::directory_iterator(tum / "rgb"), fs::directory_iterator{}), 61);
  if (!fs::exists(tool("eval"))) KESTREL_SKIP_ENVIRONMENT() << "kestrel-eval is not built";
  const auto eval = run({tool("eval").string(), "--gt", (tum / "groundtruth.txt").string(), "--est",
                         (tum / "groundtruth.txt").string(), "--frames", (tum / "rgb.txt").string(), "--json"});
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  // Every frame scored, and every error exactly zero.
  EXPECT_NE(eval.out.find("\"count\": 61,"), std::string::npos) << eval.out;
  std::istringstream json(eval.out);
  std::string token;
  int rmse_fields = 0;
  while (json >> token) {
    if (token.find("\"rmse\"") == std::string::npos) continue;
    ++rmse_fields;
    std::string value;
    json >> value;
    if (token.back() != ':') json >> value;  // "rmse" : value
    EXPECT_LT(std::abs(std::stod(value)), 1e-9) << token << " " << value;  // zero up to rounding
  }
  EXPECT_GE(rmse_fields, 1) << eval.out;
}

TEST(SimToolTest, SameSeedGivesTheSameLogBytes) {
  TempDir dir;
  const auto once = [&](const std::string& seed, const std::string& name) {
    const auto r = run({tool("sim").string(), "--world", "office", "--flight", "figure8", "--duration", "0.4",
                        "--seed", seed, "--log", (dir / name).string(), "-q"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return kestrel::test::read_file(dir / name);
  };
  const std::string a = once("3", "a.lcmlog"), b = once("3", "b.lcmlog"), c = once("4", "c.lcmlog");
  EXPECT_GT(a.size(), 100000u);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == c);
}

// Live: published inside a private network namespace, recorded by the stock lcm-logger, and
// read back by kestrel-eval (GROUND_TRUTH at 200 Hz).
TEST(SimToolTest, LivePublishingReachesAnLcmLogger) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  TempDir dir;
  const std::string log = (dir / "live.lcmlog").string();
  const std::string script =
      lcm_url_export() +
      "(lcm-logger -f '" + log + "' >/dev/null 2>&1 & echo $! > '" + (dir / "pid").string() + "') && " +
      kestrel::test::wait_for_lcm_listener_sh() + " && '" +
      tool("sim").string() + "' --world office --flight hover --duration 1 --rate 0 -q && sleep 1 && "
      "kill $(cat '" + (dir / "pid").string() + "')";
  const auto r = kestrel::test::run_isolated(script, 200.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames: 31"), std::string::npos) << r.out;
  if (!fs::exists(tool("eval"))) KESTREL_SKIP_ENVIRONMENT() << "kestrel-eval is not built";
  const auto eval = run({tool("eval").string(), "--est", log + ":GROUND_TRUTH", "--to-tum", (dir / "gt.txt").string()});
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  // 201 sent (0 .. 1 s at 200 Hz); UDP may drop a few when the logger falls behind.
  EXPECT_GE(data_lines(dir / "gt.txt"), 180);
  EXPECT_LE(data_lines(dir / "gt.txt"), 201);
}

// Closed loop over LCM: a VEHICLE_COMMAND (velocity 0.3 m/s along world x, played by the
// stock lcm-logplayer once GROUND_TRUTH has reached half a second into the flight) moves the
// simulated vehicle, as its GROUND_TRUTH recorded by a LiveSystem (test/support/live_system.h)
// shows; before it the vehicle holds its start.
TEST(SimToolTest, VehicleFliesAVehicleCommandReceivedOverLcm) {
  if (const std::string why = kestrel::test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here: " << why;
  if (!fs::exists(tool("eval"))) KESTREL_SKIP_ENVIRONMENT() << "kestrel-eval is not built";
  TempDir dir;
  const std::string log = (dir / "live.lcmlog").string(), commands = (dir / "command.lcmlog").string();
  {
    kestrel::vehicle_command_t c{};
    c.mode = kestrel::vehicle_command_t::MODE_VELOCITY;
    c.velocity[0] = 0.3;
    kestrel::transport::LogWriter writer(commands);
    writer.write_message(kestrel::channel::kVehicleCommand, 0, c);
  }
  {
    kestrel::test::LiveSystem live(dir / "processes", {{kestrel::channel::kGroundTruth}, log, {}});
    live.start("sim", {tool("sim").string(), "--world", "office", "--flight", "vehicle", "--vehicle-feedback", "truth",
                       "--duration", "4", "--camera-rate", "3", "-q"});
    // The flight is on the wire (so the sim has subscribed); half a second into it, the command.
    std::optional<int64_t> start;
    ASSERT_TRUE(live.wait_for<kestrel::ground_truth_t>(
        kestrel::channel::kGroundTruth,
        [&](const kestrel::ground_truth_t& m) {
          if (!start) start = m.utime;
          return m.utime >= *start + 500'000;
        },
        60.0, "the flight's first half second"))
        << live.output("sim");
    live.run("logplayer",
             {"env", "LCM_DEFAULT_URL=" + std::string(kestrel::transport::kDefaultLcmUrl), "lcm-logplayer", commands},
             60.0);
    live.exit_status("sim", 200.0);
    live.finish();
  }
  const auto eval = run({tool("eval").string(), "--est", log + ":GROUND_TRUTH", "--to-tum", (dir / "gt.txt").string()});
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  std::ifstream in(dir / "gt.txt");
  std::string line;
  std::vector<std::array<double, 3>> p;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t, x, y, z;
    fields >> t >> x >> y >> z;
    p.push_back({x, y, z});
  }
  ASSERT_GE(p.size(), 600u);
  // Held for the first quarter second (wind only), then carried along x.
  EXPECT_LT(std::hypot(p[50][0] - p[0][0], p[50][1] - p[0][1]), 0.02);
  EXPECT_GT(p.back()[0] - p[0][0], 0.2);
  EXPECT_LT(p.back()[0] - p[0][0], 0.3 * 3.5);
  EXPECT_LT(std::abs(p.back()[1] - p[0][1]), 0.1);
}

// --lockstep with no other process: the sim finds only itself (its own Node consumes
// VEHICLE_COMMAND and STATE, which nobody sends), waits the discovery's settling second, then
// flies the whole flight with nothing to wait for.
TEST(SimToolTest, LockstepWithoutOtherProcessesFliesTheWholeFlight) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  const std::string script =
      lcm_url_export() + "'" + tool("sim").string() + "' --world room --flight vehicle --duration 0.5 --lockstep 1.5";
  const auto r = kestrel::test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("frames: 16\n"), std::string::npos) << r.out;  // 0 .. 0.5 s at 30 Hz
  EXPECT_NE(r.out.find("imu samples: 101\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lockstep processes: 1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("process sim (pid"), std::string::npos) << r.err;
}

// --lockstep expecting a process that never comes: exit 1 naming it, within the discovery
// timeout, and no flight.
TEST(SimToolTest, LockstepExpectingAnAbsentProcessFailsNamingIt) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  const std::string script = lcm_url_export() + "'" + tool("sim").string() +
                             "' --world room --flight vehicle --duration 0.5 --lockstep 1 --expect nobody";
  const auto r = kestrel::test::run_isolated(script, 120.0);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("no heartbeat within 10.0 s from: nobody"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("frames:"), std::string::npos) << r.out;
}

// The point of lock-step: a closed-loop flight (the vehicle hovering on the STATE that the VO
// and the estimator make of its own sensors) is the same on any machine. Flown twice, the
// second time with two busy loops competing for the machine's cores, the recordings' STATE
// and GROUND_TRUTH are the same bytes: every STATE reached the vehicle's controller before
// its next step, whatever the load.
TEST(SimToolTest, LockstepClosedLoopIsTheSameUnderLoad) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  TempDir dir;
  const auto fly = [&](const std::string& name, bool loaded) {
    const std::string rec = (dir / (name + ".lcmlog")).string();
    const std::string hogs = loaded ? "sh -c 'while :; do :; done' & H1=$!; sh -c 'while :; do :; done' & H2=$!; " : "";
    const std::string unhog = loaded ? "kill $H1 $H2; " : "";
    const std::string script =
        lcm_url_export() + hogs + "'" + tool("vo").string() + "' -q & V=$!; '" + tool("estimator").string() +
        "' -q --init-position 8,3.5,1.3 & E=$!; '" + tool("sim").string() +
        "' --world room --flight vehicle --duration 3 --lockstep 20 --expect vo,estimator --record " +
        kestrel::test::quoted(rec) + "; S=$?; " + unhog + "kill -INT $V $E; wait $V $E; exit $S";
    const auto r = kestrel::test::run_isolated(script, 240.0);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::vector<std::string> out;
    kestrel::transport::LogReader log(rec);
    while (auto e = log.next())
      if (e->channel == kestrel::channel::kState || e->channel == kestrel::channel::kGroundTruth)
        out.push_back(e->channel + std::to_string(e->timestamp) + std::string(e->data.begin(), e->data.end()));
    return out;
  };
  const auto calm = fly("calm", false);
  const auto loaded = fly("loaded", true);
  ASSERT_GT(calm.size(), 600u * 2 - 100);  // 3 s of 200 Hz truth, and STATE once it settled
  EXPECT_TRUE(calm == loaded) << calm.size() << " vs " << loaded.size() << " messages";
}

TEST(SimToolTest, BadInputIsOneLineNamingTheFileWithExitCode3) {
  TempDir dir;
  const fs::path world = dir / "bad.world";
  std::ofstream(world) << "kestrel-world 1\nmaterial p plaster\nwall p 0 0 one 1\n";
  const auto bad = run({tool("sim").string(), "--world", world.string(), "--log", (dir / "x.lcmlog").string()});
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_NE(bad.err.find("kestrel-sim: error: " + world.string() + ":3: wall: x1 'one'"), std::string::npos) << bad.err;

  // Naming no world there is, or stata without its map, is a usage error (exit 2), as is a
  // flight there is not; a missing world file is input that is not there (exit 3).
  const auto no_map = run({tool("sim").string(), "--world", "stata", "--log", (dir / "x.lcmlog").string()});
  EXPECT_EQ(no_map.exit_code, 2);
  EXPECT_NE(no_map.err.find("kestrel-sim: error: --world: world 'stata' needs an occupancy map (--map"),
            std::string::npos) << no_map.err;
  for (const std::string& name : std::vector<std::string>{"atlantis", (dir / "bad.txt").string()}) {
    const auto unknown = run({tool("sim").string(), "--world", name, "--log", (dir / "x.lcmlog").string()});
    EXPECT_EQ(unknown.exit_code, 2) << unknown.err;
    EXPECT_NE(unknown.err.find("kestrel-sim: error: --world: unknown world '" + name + "'"), std::string::npos)
        << unknown.err;
  }
  const auto absent = run({tool("sim").string(), "--world", (dir / "absent.world").string(), "--log",
                           (dir / "x.lcmlog").string()});
  EXPECT_EQ(absent.exit_code, 3) << absent.err;

  const auto flight = run({tool("sim").string(), "--flight", "barrel-roll", "--log", (dir / "x.lcmlog").string()});
  EXPECT_EQ(flight.exit_code, 2);
  EXPECT_NE(flight.err.find("unknown flight 'barrel-roll'"), std::string::npos) << flight.err;

  const auto help = run({tool("sim").string(), "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--flight"), std::string::npos);

  // sim-realism takes the same worlds and flights, with the same exit codes, and says so
  // before it reads its TUM folder (absent here: that would be exit 3).
  const std::string no_tum = (dir / "no-tum").string();
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c : std::vector<Case>{{{"--world", "atlantis"}, "--world: unknown world 'atlantis'"},
                                         {{"--world", "stata"}, "--world: world 'stata' needs an occupancy map"},
                                         {{"--flight", "barrel-roll"}, "unknown flight 'barrel-roll'"}}) {
    std::vector<std::string> argv{tool("sim-realism").string(), "--tum", no_tum};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const auto r = run(argv);
    EXPECT_EQ(r.exit_code, 2) << c.args[1] << ": " << r.err;
    EXPECT_NE(r.err.find("kestrel-sim-realism: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  const auto absent_tum = run({tool("sim-realism").string(), "--tum", no_tum});
  EXPECT_EQ(absent_tum.exit_code, 3) << absent_tum.err;
}

}  // namespace
