// kestrel-follow as a process, under lock-step replay in a private network: a PLAN and a
// vehicle moving along it (STATE at 200 Hz) in, VEHICLE_COMMANDs out, one per 20 ms of sensor
// time, position commands on the path; a PLAN without a path stops it with a hold. And the
// tool's bad input: a waypoint file with a bad line exits 3 naming the line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

kestrel::state_t state(int64_t utime, double x) {
  kestrel::state_t m{};
  m.utime = utime;
  m.status = kestrel::state_t::STATUS_OK;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, 0.0, 1.0);
  m.T_world_body = transport::to_message(T);
  return m;
}

kestrel::plan_t plan(int64_t utime, bool ok) {
  kestrel::plan_t p{};
  p.utime = utime;
  p.request_id = ok ? 1 : 2;
  p.status = ok ? kestrel::plan_t::STATUS_OK : kestrel::plan_t::STATUS_NO_PATH;
  if (ok) {
    p.waypoints = {{0, 0, 1, 0}, {4, 0, 1, 0}};
    p.covariance_trace = {0.4, 1.0};
    p.num_waypoints = 2;
  }
  return p;
}

TEST(FollowTool, TurnsAPlanAndStatesIntoCommandsUnderLockStepReplay) {
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  if (!std::filesystem::exists(test::tool("replay"))) KESTREL_SKIP_ENVIRONMENT() << test::tool("replay") << " is not built";
  test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string(), out = (dir / "out.lcmlog").string();
  {
    transport::LogWriter log(in);
    const int64_t t0 = 1'000'000;
    log.write_message("PLAN", t0, plan(t0, true));
    // 1 s at 0.5 m/s along the path, then the planner says there is no path.
    for (int k = 1; k <= 200; ++k) log.write_message("STATE", t0 + 5'000 * k, state(t0 + 5'000 * k, 0.0025 * k));
    log.write_message("PLAN", t0 + 1'000'001, plan(t0 + 1'000'001, false));
    for (int k = 201; k <= 220; ++k) log.write_message("STATE", t0 + 5'000 * k, state(t0 + 5'000 * k, 0.5));
    log.close();
  }
  const std::string script = test::tool("follow").string() + " -q & F=$!; " + test::tool("replay").string() + " " +
                             in + " --expect follow --record " + out + "; R=$?; kill -INT $F; wait $F; exit $R";
  const auto r = test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  transport::LogReader log(out);
  int position = 0, hold = 0;
  double last_x = -1.0;
  while (auto e = log.next()) {
    if (e->channel != "VEHICLE_COMMAND") continue;
    const auto c = transport::decode_message<kestrel::vehicle_command_t>(e->data.data(), e->data.size(), "VEHICLE_COMMAND");
    if (c.mode == kestrel::vehicle_command_t::MODE_POSITION) {
      ++position;
      EXPECT_EQ(hold, 0) << "no position command after the hold";
      EXPECT_GE(c.position[0], last_x) << "the set point moves along the path";
      EXPECT_NEAR(c.position[1], 0.0, 1e-12);
      EXPECT_NEAR(c.velocity[0], 0.5, 1e-12);
      last_x = c.position[0];
    } else {
      EXPECT_EQ(c.mode, kestrel::vehicle_command_t::MODE_HOLD);
      EXPECT_NEAR(c.position[0], 0.5, 1e-12) << "holds where the vehicle is";
      ++hold;
    }
  }
  EXPECT_EQ(position, 50) << "one command per 20 ms over 1 s";
  EXPECT_EQ(hold, 1) << "one hold after the plan without a path, then silence";
}

TEST(FollowTool, WithoutLcmFollowAndGotoExit4NamingTheUrl) {
  for (const char* tool : {"follow", "goto"}) {
    std::vector<std::string> argv = {test::tool(tool).string(), "--lcm-url", "nosuchprovider://"};
    if (std::string(tool) == "goto") argv.insert(argv.end(), {"--goal", "1", "2", "1", "0"});
    const auto r = test::run(argv);
    EXPECT_EQ(r.exit_code, 4) << tool << ": " << r.err;
    EXPECT_NE(r.err.find("nosuchprovider://"), std::string::npos) << r.err;
  }
}

TEST(FollowTool, AWaypointFileWithABadLineExits3NamingTheLine) {
  test::TempDir dir;
  const std::string path = (dir / "w.txt").string();
  std::ofstream(path) << "0 0 1 0\n1 0 1\n";
  const auto r = test::run({test::tool("follow").string(), "--waypoints", path});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("w.txt:2"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace kestrel
