// kestrel-follow as a process, under lock-step replay in a private network: a PLAN and a
// vehicle moving along it (STATE at 200 Hz) in, VEHICLE_COMMANDs out, one per 20 ms of sensor
// time, position commands on the path; a PLAN without a path stops it with a hold. kestrel
// goto --wait on a plan that passes by the goal before it ends there. And the tools' bad input:
// a waypoint file with a bad line exits 3 naming the line.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <thread>

#include "common/transport/convert.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "test/support/live_system.h"
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

// A plan the belief model bent (here a loop out and back) may pass by its goal before it ends
// there; goto --wait arrives only at the end, with its progress along the plan kept as the
// follower keeps it. Before, it said "arrived" when the vehicle first passed by, and a flight
// that went on from there ended 0.44 m from the goal (System.APlannerKilledWhileTheVehicleHovers...).
TEST(GotoTool, ArrivesAtThePlansEndNotWhereThePlanFirstPassesByTheGoal) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty())
    KESTREL_SKIP_ENVIRONMENT() << "no network namespace available: " << why;
  test::TempDir dir;
  test::LiveSystem live(dir.path(), {{"PLAN_REQUEST"}, {}, {}});
  live.start("goto", {test::tool("goto").string(), "--goal", "2", "0", "1", "0", "--wait", "--arrive-radius", "0.1",
                      "--timeout", "60"});
  lcm::LCM lcm(transport::resolve_lcm_url(""));
  ASSERT_TRUE(lcm.good());
  int64_t utime = 1'000'000;
  const auto fly_to = [&](double x, double y) {
    kestrel::state_t m = state(utime += 5'000, x);
    m.T_world_body.position[1] = y;
    lcm.publish("STATE", &m);
  };
  // STATE until goto asks.
  std::optional<kestrel::plan_request_t> request;
  for (int i = 0; i < 1000 && !request; ++i) {
    fly_to(0.0, 0.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (const auto sent = live.messages("PLAN_REQUEST"); !sent.empty())
      request = transport::decode_message<kestrel::plan_request_t>(sent[0].data.data(), sent[0].data.size(), "PLAN_REQUEST");
  }
  ASSERT_TRUE(request) << live.output("goto");
  // Out along x past the goal (2, 0), round a 1 m square loop, and back to it from above.
  const std::vector<Eigen::Vector2d> corners = {{0, 0}, {3, 0}, {3, 1}, {2, 1}, {2, 0}};
  kestrel::plan_t p{};
  p.utime = utime;
  p.request_id = request->request_id;
  p.status = kestrel::plan_t::STATUS_OK;
  for (const Eigen::Vector2d& c : corners) {
    p.waypoints.push_back({c.x(), c.y(), 1.0, 0.0});
    p.covariance_trace.push_back(0.1);
  }
  p.num_waypoints = static_cast<int32_t>(corners.size());
  lcm.publish("PLAN", &p);
  // Along the plan in 2 cm steps: through the goal at 2 m, on to the end at 6 m.
  const auto fly_along = [&](double from_s, double to_s) {
    for (double s = from_s; s <= to_s + 1e-9; s += 0.02) {
      double left = s;
      size_t i = 0;
      while (i + 2 < corners.size() && left > (corners[i + 1] - corners[i]).norm()) left -= (corners[i + 1] - corners[i]).norm(), ++i;
      const Eigen::Vector2d at = corners[i] + left * (corners[i + 1] - corners[i]).normalized();
      fly_to(at.x(), at.y());
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  };
  fly_along(0.0, 2.5);
  EXPECT_FALSE(live.wait_exit("goto", 1.0)) << "goto stopped where the plan first passed by the goal:\n"
                                            << live.output("goto");
  fly_along(2.52, 6.0);
  // Holding at the end until goto has seen it (at most 30 s: a slow goto under the sanitizers).
  std::optional<int> went;
  for (int i = 0; i < 1500 && !(went = live.wait_exit("goto", 0.0)); ++i) {
    fly_to(2.0, 0.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(went) << "goto did not arrive at the end:\n" << live.output("goto");
  EXPECT_EQ(*went, 0) << live.output("goto");
  EXPECT_NE(live.output("goto").find("arrived"), std::string::npos) << live.output("goto");
  live.stop_all();
  live.finish();
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
