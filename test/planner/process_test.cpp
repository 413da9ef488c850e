// kestrel-planner as a process, in a private network namespace under lock-step replay: a log
// with an OctoMap of a room split by a wall with one gap, a STATE and six PLAN_REQUESTs (BRM
// by both label rules, PRM, bad ones) goes through the running planner twice (RESET
// between). Each request gets one PLAN with the right status; the plans run from their start
// to their goal through the gap, clear of the known walls, with the predicted tr(Sigma)
// starting at the request's (or the state's); the second replay answers identically. The
// dominance request runs with --dominance-slack 0 (exact).
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <sstream>

#include "common/error.h"
#include "common/transport/channels.h"
#include "kestrel/plan_covariance_t.hpp"
#include "common/transport/log_file.h"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"
#include "test/support/test_support.h"

namespace kestrel::planner {
namespace {

// The room: 8 x 4 m, walls 0.1 m thick all round, a dividing wall at x in [3.9, 4.1] from
// the south wall up to y = 2.6, leaving a 1.3 m gap to the north wall.
constexpr double kGapY = 2.6;

bool wall_at(double x, double y) {
  return x < 0.1 || x > 7.9 || y < 0.1 || y > 3.9 || (x > 3.9 && x < 4.1 && y < kGapY);
}

kestrel::octomap_t room_octomap() {
  octomap::OcTree tree(0.1);
  for (double x = 0.05; x < 8.0; x += 0.1)
    for (double y = 0.05; y < 4.0; y += 0.1)
      for (double z = 0.05; z < 2.5; z += 0.1) tree.updateNode(octomap::point3d(x, y, z), wall_at(x, y));
  std::ostringstream bytes;
  tree.writeBinary(bytes);
  const std::string s = bytes.str();
  kestrel::octomap_t m{};
  m.utime = 1000;
  m.revision = 1;
  m.resolution = 0.1;
  m.format = kestrel::octomap_t::FORMAT_BINARY;
  m.data.assign(s.begin(), s.end());
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

kestrel::plan_request_t request(int64_t id, double gx, double gy) {
  kestrel::plan_request_t r{};
  r.utime = 1000 + id;
  r.request_id = id;
  r.start_mode = kestrel::plan_request_t::START_GIVEN;
  r.start[0] = 1.5, r.start[1] = 1.0, r.start[2] = 1.0, r.start[3] = 0.0;
  r.start_covariance_trace = 0.4;
  r.goal[0] = gx, r.goal[1] = gy, r.goal[2] = 1.0, r.goal[3] = 0.0;
  r.planner = kestrel::plan_request_t::PLANNER_BRM;
  r.objective = kestrel::plan_request_t::OBJECTIVE_MIN_GOAL_UNCERTAINTY;
  return r;
}

void write_input_log(const std::string& path) {
  transport::LogWriter log(path);
  log.write_message(channel::kPlanRequest, 100, request(1, 6.5, 1.0));  // before any map
  log.write_message(channel::kMapOctomap, 1000, room_octomap());
  kestrel::state_t s{};
  s.utime = 1500;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body.position[0] = 1.5, s.T_world_body.position[1] = 3.0, s.T_world_body.position[2] = 1.0;
  s.T_world_body.orientation[0] = 1.0;  // w
  s.cov_dim = 9;
  s.covariance.assign(9, std::vector<double>(9, 0.0));
  for (int i = 0; i < 9; ++i) s.covariance[i][i] = i == 8 ? 0.02 : 0.01;  // tr over x, y, z, yaw: 0.05
  log.write_message(channel::kState, 1500, s);
  // A filter (re)started in a world of its own, not yet usable (--await-world): not the start.
  kestrel::state_t unsettled = s;
  unsettled.utime = 1600;
  unsettled.status = kestrel::state_t::STATUS_INITIALIZING;
  unsettled.T_world_body.position[0] = 6.0;
  log.write_message(channel::kState, 1600, unsettled);
  log.write_message(channel::kPlanRequest, 2002, request(2, 6.5, 1.0));  // BRM through the gap
  kestrel::plan_request_t from_state = request(3, 6.5, 3.2);
  from_state.start_mode = kestrel::plan_request_t::START_FROM_STATE;
  from_state.planner = kestrel::plan_request_t::PLANNER_PRM;
  log.write_message(channel::kPlanRequest, 2003, from_state);
  log.write_message(channel::kPlanRequest, 2004, request(4, 4.0, 1.0));  // inside the dividing wall
  kestrel::plan_request_t bad = request(5, 6.5, 1.0);
  bad.planner = 7;
  log.write_message(channel::kPlanRequest, 2005, bad);
  kestrel::plan_request_t dominance = request(6, 6.5, 1.0);
  dominance.planner = kestrel::plan_request_t::PLANNER_BRM_DOMINANCE;
  log.write_message(channel::kPlanRequest, 2006, dominance);
  log.close();
}

std::vector<kestrel::plan_t> plans(const std::string& path) {
  return transport::read_messages<kestrel::plan_t>(path, channel::kPlan);
}

// Every point of the polyline keeps `clearance` from the walls; returns the largest y where it
// crosses the dividing wall's plane x = 4.
double check_path(const kestrel::plan_t& p, double clearance) {
  double crossing_y = -1.0;
  for (int i = 1; i < p.num_waypoints; ++i)
    for (int k = 0; k <= 100; ++k) {
      const double t = k / 100.0;
      const double x = (1 - t) * p.waypoints[i - 1][0] + t * p.waypoints[i][0];
      const double y = (1 - t) * p.waypoints[i - 1][1] + t * p.waypoints[i][1];
      for (double dx = -clearance; dx <= clearance; dx += clearance / 4)
        for (double dy = -clearance; dy <= clearance; dy += clearance / 4)
          if (dx * dx + dy * dy <= clearance * clearance) {
            EXPECT_FALSE(wall_at(x + dx, y + dy)) << x << " " << y;
          }
      if (std::abs(x - 4.0) < 0.05) crossing_y = std::max(crossing_y, y);
    }
  return crossing_y;
}

TEST(PlannerProcess, AnswersEveryRequestOverLcmAndRepeatsAfterReset) {
  if (!kestrel::test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  kestrel::test::TempDir dir;
  const std::string in = (dir / "in.lcmlog").string();
  write_input_log(in);
  const std::string planner = kestrel::test::tool("planner").string();
  const std::string replay = kestrel::test::tool("replay").string();
  const std::string script =
      "'" + planner + "' -q --sensor kinect --dominance-slack 0 & P=$!; "
      "'" + replay + "' '" + in + "' --expect planner --record '" + (dir / "a.lcmlog").string() + "' >/dev/null && "
      "'" + replay + "' '" + in + "' --expect planner --record '" + (dir / "b.lcmlog").string() + "' >/dev/null; "
      "R=$?; kill $P; wait $P; exit $R";
  const kestrel::test::RunResult r =
      kestrel::test::run_isolated(script, 120.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  const auto a = plans((dir / "a.lcmlog").string()), b = plans((dir / "b.lcmlog").string());
  ASSERT_EQ(a.size(), 6u);
  ASSERT_EQ(b.size(), a.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].request_id, static_cast<int64_t>(i + 1));
  EXPECT_EQ(a[0].status, kestrel::plan_t::STATUS_NO_MAP);
  EXPECT_EQ(a[3].status, kestrel::plan_t::STATUS_GOAL_IN_COLLISION);
  EXPECT_EQ(a[4].status, kestrel::plan_t::STATUS_BAD_REQUEST);
  EXPECT_EQ(a[4].message, "PLAN_REQUEST: unknown planner 7");  // answered, naming the field
  for (int k : {1, 2, 5}) {
    const kestrel::plan_t& p = a[k];
    ASSERT_EQ(p.status, kestrel::plan_t::STATUS_OK) << p.message;
    ASSERT_GE(p.num_waypoints, 2);
    const double sx = k == 2 ? 3.0 : 1.0, gy = k == 2 ? 3.2 : 1.0;
    EXPECT_NEAR(p.waypoints[0][0], 1.5, 1e-9) << "plan " << k + 1 << " starts from the usable STATE";
    EXPECT_NEAR(p.waypoints[0][1], sx, 1e-9);
    EXPECT_NEAR(p.waypoints.back()[0], 6.5, 1e-9);
    EXPECT_NEAR(p.waypoints.back()[1], gy, 1e-9);
    EXPECT_NEAR(p.covariance_trace[0], k == 2 ? 0.05 : 0.4, 1e-9);
    for (double tr : p.covariance_trace) EXPECT_GT(tr, 0.0);
    // Clear of the walls by the vehicle radius less the map's half-cell rounding.
    EXPECT_GT(check_path(p, 0.3 - 0.05), kGapY) << "plan " << k + 1 << " does not go through the gap";
    EXPECT_GE(p.length, 5.0);
  }
  // Each plan with a path is followed by its PLAN_COVARIANCE, whose traces are the plan's.
  const auto covariances =
      transport::read_messages<kestrel::plan_covariance_t>((dir / "a.lcmlog").string(), channel::kPlanCovariance);
  ASSERT_EQ(covariances.size(), 3u);
  for (size_t j = 0; j < covariances.size(); ++j) {
    const kestrel::plan_t& p = a[std::vector<size_t>{1, 2, 5}[j]];
    const kestrel::plan_covariance_t& c = covariances[j];
    EXPECT_EQ(c.request_id, p.request_id);
    EXPECT_EQ(c.utime, p.utime);
    ASSERT_EQ(c.num_waypoints, p.num_waypoints);
    for (int i = 0; i < c.num_waypoints; ++i) {
      const auto& m = c.covariance[static_cast<size_t>(i)];
      EXPECT_NEAR(m[0] + m[5] + m[10] + m[15], p.covariance_trace[static_cast<size_t>(i)], 1e-12) << i;
    }
  }
  // A negative slack is refused on the command line.
  EXPECT_EQ(kestrel::test::run({planner, "--dominance-slack", "-0.1"}, 10.0).exit_code, kExitUsage);

  // The second replay (after a RESET) gives the same plans.
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(b[i].status, a[i].status);
    EXPECT_EQ(b[i].waypoints, a[i].waypoints);
    EXPECT_EQ(b[i].covariance_trace, a[i].covariance_trace);
  }
}

}  // namespace
}  // namespace kestrel::planner
