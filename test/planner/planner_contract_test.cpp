// The contract every planner keeps with every sampler (the shape of OMPL's PlannerTest): one
// set of problems, run through the planner the process flies (OnlinePlanner) for each search
// (PRM, BRM with the paper's trace pruning, BRM with covariance dominance, BRM's shortest path
// under a bound) × each sampler of planner/samplers.h. A new planner or sampler joins by being
// listed; nothing here is specific to one of them.
//
// The world: a 12 m × 6 m room, walls 0.2 m thick all round, split by a wall at x = 6 m from
// the floor plan's bottom edge up to y = 3.5 m, so that every path from the left half to the
// right goes through the 2.3 m gap at the top.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "planner/configuration_space.h"
#include "planner/grid_environment.h"
#include "planner/online_planner.h"
#include "planner/samplers.h"

namespace kestrel::planner {
namespace {

OccupancyGrid split_room() {
  OccupancyGrid g = make_grid(240, 120, 0.05, 0.025, 0.025);
  fill_rect(g, 0.0, 0.0, 12.0, 0.2, OccupancyGrid::kOccupied);
  fill_rect(g, 0.0, 5.8, 12.0, 6.0, OccupancyGrid::kOccupied);
  fill_rect(g, 0.0, 0.0, 0.2, 6.0, OccupancyGrid::kOccupied);
  fill_rect(g, 11.8, 0.0, 12.0, 6.0, OccupancyGrid::kOccupied);
  fill_rect(g, 5.9, 0.0, 6.1, 3.5, OccupancyGrid::kOccupied);
  return g;
}

// How a PlanQuery asks for each search.
struct Search {
  std::string name;
  bool brm = true;
  BrmPruning pruning = BrmPruning::kTrace;
  BrmObjective objective = BrmObjective::kMinGoalUncertainty;
};

std::vector<Search> searches() {
  return {{"prm", false},
          {"brm", true, BrmPruning::kTrace},
          {"brmdominance", true, BrmPruning::kCovarianceDominance},
          {"brmbounded", true, BrmPruning::kTrace, BrmObjective::kShortestBounded}};
}

const Config kStart(1.5, 1.5, 1.0, 0.0);
const Config kGoal(10.5, 1.5, 1.0, 0.0);
constexpr double kStartTrace = 0.04;
constexpr double kBound = 50.0;  // tr(Sigma) m^2-and-rad^2: loose, so that it bounds without blocking

class PlannerContract : public ::testing::TestWithParam<std::tuple<Search, std::string>> {
 protected:
  PlannerContract() : planner_(options()) { planner_.set_map(split_room()); }

  static OnlinePlannerOptions options() {
    OnlinePlannerOptions o;
    o.sampler = std::get<1>(GetParam());
    // Small roadmaps and sparse features: the contract is about what any plan must be, and
    // each of its 75 cases plans several times under the sanitizers.
    o.roadmap.samples = 40;
    o.roadmap.max_samples = 300;  // grown while unconnected; a walled-up room stops here
    o.roadmap.max_neighbours = 8;
    o.feature_density_per_m2 = 1.0;
    return o;
  }

  static PlanQuery query(const Search& s, const Config& start = kStart, const Config& goal = kGoal) {
    PlanQuery q;
    q.request_id = 3;
    q.start = start;
    q.start_trace = kStartTrace;
    q.goal = goal;
    q.brm = s.brm;
    q.pruning = s.pruning;
    q.objective = s.objective;
    if (s.objective == BrmObjective::kShortestBounded) q.max_trace = kBound;
    return q;
  }

  OnlinePlanner planner_;
};

TEST_P(PlannerContract, APathRunsFromStartToGoalThroughFreeSpaceAndIsMeasuredRight) {
  const Search& s = std::get<0>(GetParam());
  const PlanAnswer a = planner_.plan(query(s));
  ASSERT_EQ(a.status, PlanAnswer::kOk) << a.message;
  ASSERT_GE(a.waypoints.size(), 3u) << "the wall is in the way of the straight line";
  EXPECT_EQ(a.waypoints.front(), kStart);
  EXPECT_EQ(a.waypoints.back(), kGoal);
  // Every leg free for the vehicle, in the space the planner was given.
  const OnlinePlannerOptions o = options();
  const GridEnvironment env(split_room(), o.map_z_min_m, o.map_z_max_m);
  const ConfigurationSpace space(env, o.space);
  double length = 0.0;
  for (size_t i = 1; i < a.waypoints.size(); ++i) {
    EXPECT_TRUE(space.motion_valid(a.waypoints[i - 1], a.waypoints[i])) << "leg " << i;
    length += ConfigurationSpace::distance(a.waypoints[i - 1], a.waypoints[i]);
  }
  EXPECT_NEAR(a.length_m, length, 1e-9);
  EXPECT_GT(a.length_m, (kGoal - kStart).head<3>().norm()) << "shorter than the straight line";
  // The predicted uncertainty: one per waypoint, from the start's, finite and positive.
  ASSERT_EQ(a.traces.size(), a.waypoints.size());
  EXPECT_NEAR(a.traces.front(), kStartTrace, 1e-12);
  for (const double t : a.traces) EXPECT_TRUE(std::isfinite(t) && t > 0.0) << t;
  if (s.objective == BrmObjective::kShortestBounded) {
    for (const double t : a.traces) EXPECT_LE(t, kBound);
  }
}

TEST_P(PlannerContract, TheSameRequestGivesTheSamePlan) {
  const PlanQuery q = query(std::get<0>(GetParam()));
  const PlanAnswer a = planner_.plan(q), b = planner_.plan(q);
  ASSERT_EQ(a.status, PlanAnswer::kOk) << a.message;
  EXPECT_EQ(a.waypoints, b.waypoints);
  EXPECT_EQ(a.traces, b.traces);
  EXPECT_EQ(a.length_m, b.length_m);
}

// What the searches other than PRM keep with PRM (instantiated without PRM itself, where it
// could not fail).
class PlannerContractAgainstPrm : public PlannerContract {};

TEST_P(PlannerContractAgainstPrm, NoPathIsShorterThanPrmsOnTheSameRoadmap) {
  // The same request id and sampler build the same roadmap; PRM is its shortest path.
  const PlanAnswer a = planner_.plan(query(std::get<0>(GetParam())));
  const PlanAnswer prm = planner_.plan(query(searches()[0]));
  ASSERT_EQ(a.status, PlanAnswer::kOk) << a.message;
  ASSERT_EQ(prm.status, PlanAnswer::kOk) << prm.message;
  EXPECT_GE(a.length_m, prm.length_m - 1e-9);
}

TEST_P(PlannerContract, ImpossibleRequestsAreAnsweredNotPlanned) {
  const Search& s = std::get<0>(GetParam());
  EXPECT_EQ(planner_.plan(query(s, Config(6.0, 2.0, 1.0, 0.0))).status, PlanAnswer::kStartInCollision);
  EXPECT_EQ(planner_.plan(query(s, kStart, Config(0.1, 3.0, 1.0, 0.0))).status, PlanAnswer::kGoalInCollision);
  EXPECT_EQ(planner_.plan(query(s, kStart, Config(10.5, 1.5, 3.0, 0.0))).status, PlanAnswer::kGoalInCollision)
      << "a goal off the flight band";
  // The gap walled up: free on both sides, no way between.
  OccupancyGrid closed = split_room();
  fill_rect(closed, 5.9, 0.0, 6.1, 6.0, OccupancyGrid::kOccupied);
  OnlinePlannerOptions fixed = options();
  fixed.roadmap.max_samples = 0;  // no growth: an unconnected roadmap is the answer at once
  OnlinePlanner blocked(fixed);
  blocked.set_map(closed);
  EXPECT_EQ(blocked.plan(query(s)).status, PlanAnswer::kNoPath);
}

using Case = std::tuple<Search, std::string>;

// Each search paired with each sampler; `belief_only` keeps the BRM searches.
std::vector<Case> cases(bool belief_only) {
  std::vector<Case> out;
  for (const Search& s : searches()) {
    if (belief_only && !s.brm) continue;
    for (const std::string& sampler : sampler_names()) out.emplace_back(s, sampler);
  }
  return out;
}
std::vector<Case> every_search_and_sampler() { return cases(false); }
std::vector<Case> every_belief_search_and_sampler() { return cases(true); }

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string sampler = std::get<1>(info.param);
  for (char& c : sampler)
    if (c == '-') c = '_';
  return std::get<0>(info.param).name + "_" + sampler;
}

INSTANTIATE_TEST_SUITE_P(EveryPlannerAndSampler, PlannerContract,
                         ::testing::ValuesIn(every_search_and_sampler()), case_name);
INSTANTIATE_TEST_SUITE_P(EveryBeliefPlannerAndSampler, PlannerContractAgainstPrm,
                         ::testing::ValuesIn(every_belief_search_and_sampler()), case_name);

}  // namespace
}  // namespace kestrel::planner
