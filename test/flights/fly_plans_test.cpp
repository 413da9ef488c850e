// kestrel fly-plans as a user runs it: one short BRM plan in the room flown in closed loop with
// the whole system (sim vehicle, vo, estimator, follow, slam, mapper; lock-step), scored
// against the truth; and the usage errors.

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

// A 2 m pair in the room, planned with BRM-SU and flown: the vehicle gets there by the truth
// (within the tool's 0.3 m, and the follower's 0.1 m with the wind's sway), without touching
// the room, and the estimator it flies on stays within 5 cm of the truth.
TEST(FlyPlans, ABrmPlanInTheRoomIsFlownToItsGoalOnTheEstimatorsState) {
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  test::TempDir dir;
  const auto r = test::run({test::tool("fly-plans").string(), "--world", "room", "--start", "8,3.5,1.3,0", "--goal",
                            "10,3.5,1.3,0", "--planners", "brm:su", "--seeds", "1", "--out", dir.path().string(),
                            "--vo-set", "keyframe.floor_cap_fraction=0.7"},  // the simulator profile's, passed through
                           500.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json flights = nlohmann::json::parse(test::read_file(dir / "flights.json"));
  ASSERT_EQ(flights.size(), 1u) << flights.dump(2);
  const auto& f = flights[0];
  ASSERT_TRUE(f["flown"].get<bool>()) << f.dump(2);
  EXPECT_TRUE(f["arrived"].get<bool>()) << f.dump(2);
  EXPECT_LT(f["final_distance_m"].get<double>(), 0.15) << f.dump(2);
  EXPECT_EQ(f["contacts"].get<int>(), 0) << f.dump(2);
  EXPECT_GT(f["states_scored"].get<int>(), 1000) << f.dump(2);
  EXPECT_LT(f["true_error_max_m"].get<double>(), 0.05) << f.dump(2);
  // Overconfident today (NEES 23: a steady 1.5 cm off under a 3 mm sigma, once SLAM's
  // corrections have moved it; issue 39's consistency item), but not blind: on average within
  // 10 sigma.
  EXPECT_GT(f["nees_mean"].get<double>(), 0.3) << f.dump(2);
  EXPECT_LT(f["nees_mean"].get<double>(), 100.0) << f.dump(2);
  EXPECT_GT(f["vo_frames"].get<int>(), 200) << f.dump(2);
  EXPECT_LT(f["vo_failures"].get<int>(), f["vo_frames"].get<int>() / 10) << f.dump(2);
  EXPECT_GE(f["keyframes"].get<int>(), 2) << f.dump(2);
  // What a person reads: the table and the picture, and each process's log beside the recording.
  EXPECT_NE(test::read_file(dir / "report.md").find("| 1 | brm-su | 1 | 100 % (1/1) | 100 % (1/1) |"), std::string::npos)
      << test::read_file(dir / "report.md");
  EXPECT_NE(test::read_file(dir / "report.md").find("The VO with `--set keyframe.floor_cap_fraction=0.7`"),
            std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "room_pair1.png"));
  const fs::path flight = dir / "room" / "pair1" / "brm-su" / "seed1";
  for (const char* file : {"flight.lcmlog", "waypoints.txt", "vo.log", "estimator.log", "follow.log", "slam.log",
                           "mapper.log", "sim.log"})
    EXPECT_TRUE(fs::exists(flight / file)) << file;
}

TEST(FlyPlans, UsageErrorsExitTwoNamingTheOption) {
  test::TempDir dir;
  const std::string tool = test::tool("fly-plans").string();
  const auto no_pair = test::run({tool, "--world", "room", "--out", dir.path().string()});
  EXPECT_EQ(no_pair.exit_code, 2) << no_pair.err;
  EXPECT_NE(no_pair.err.find("--start"), std::string::npos) << no_pair.err;
  const auto bad_planner = test::run({tool, "--planners", "brm:nonsense"});
  EXPECT_EQ(bad_planner.exit_code, 2) << bad_planner.err;
  EXPECT_NE(bad_planner.err.find("unknown sampler 'nonsense'"), std::string::npos) << bad_planner.err;
  const auto half_pair = test::run({tool, "--world", "room", "--start", "8,3.5,1.3,0"});
  EXPECT_EQ(half_pair.exit_code, 2) << half_pair.err;
  const auto wall = test::run({tool, "--world", "room", "--start", "-50,3.5,1.3,0", "--goal", "10,3.5,1.3,0",
                               "--out", dir.path().string()});
  EXPECT_EQ(wall.exit_code, 2) << wall.err;
  EXPECT_NE(wall.err.find("not free"), std::string::npos) << wall.err;
  // A VO setting is checked before anything flies, not by the first flight's VO dying.
  for (const char* bad : {"nope=1", "keyframe.floor_cap_fraction=2", "keyframe.floor_cap_fraction"}) {
    const auto r = test::run({tool, "--vo-set", bad, "--out", dir.path().string()});
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--vo-set"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace kestrel
