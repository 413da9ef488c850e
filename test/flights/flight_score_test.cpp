// The closed-loop flight's score on records made by hand: arrival by the truth at the end,
// the estimator's true error and its NEES under its own covariance, and the covariance where
// the truth passed each planned node.

#include <gtest/gtest.h>

#include <cmath>

#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "test/support/test_support.h"
#include "tools/flights/flight_log.h"
#include "tools/flights/flight_score.h"

namespace kestrel::flights {
namespace {

// The truth along x at 1 m/s, sampled at 10 Hz for `seconds`; STATE `offset` off, with
// covariance sigma^2 I, at every truth sample.
FlightRecord straight_flight(double seconds, const Eigen::Vector3d& offset, double sigma) {
  FlightRecord r;
  for (int i = 0; i <= static_cast<int>(std::lround(seconds * 10)); ++i) {
    const int64_t utime = 1'000'000 + i * 100'000;
    const Eigen::Vector3d p(0.1 * i, 0.0, 1.0);
    r.truth.push_back({utime, p});
    r.states.push_back({utime, true, p + offset, sigma * sigma * Eigen::Matrix3d::Identity()});
  }
  return r;
}

TEST(FlightScore, ArrivalErrorAndNeesOfAStraightFlight) {
  const FlightRecord r = straight_flight(5.0, Eigen::Vector3d(0.03, 0.04, 0.0), 0.05);  // 5 cm off, 1 sigma
  const FlightScore s = score_flight(r, Eigen::Vector3d(5.0, 0.0, 1.0), 0.3, {});
  EXPECT_TRUE(s.arrived);
  EXPECT_NEAR(s.final_distance_m, 0.0, 1e-12);
  EXPECT_NEAR(s.arrival_s, 4.7, 1e-9);  // from x = 4.7 on, within 0.3 m
  EXPECT_NEAR(s.flown_s, 5.0, 1e-12);
  EXPECT_EQ(s.states_scored, 51);
  EXPECT_NEAR(s.error_mean_m, 0.05, 1e-12);
  EXPECT_NEAR(s.error_max_m, 0.05, 1e-12);
  EXPECT_NEAR(s.nees_mean, 1.0, 1e-9);  // (0.05 / 0.05)^2
  EXPECT_NEAR(s.inside_3sigma, 1.0, 1e-12);
}

TEST(FlightScore, AFlightThatStopsShortDidNotArriveAndAnOverconfidentEstimateIsOutside3Sigma) {
  const FlightRecord r = straight_flight(4.0, Eigen::Vector3d(0.0, 0.5, 0.0), 0.05);  // 10 sigma off
  const FlightScore s = score_flight(r, Eigen::Vector3d(5.0, 0.0, 1.0), 0.3, {});
  EXPECT_FALSE(s.arrived);
  EXPECT_TRUE(std::isnan(s.arrival_s));
  EXPECT_NEAR(s.final_distance_m, 1.0, 1e-12);
  EXPECT_NEAR(s.nees_mean, 100.0, 1e-9);
  EXPECT_NEAR(s.inside_3sigma, 0.0, 1e-12);
}

TEST(FlightScore, StatesNotUsableOrWithoutTruthAreNotScored) {
  FlightRecord r = straight_flight(1.0, Eigen::Vector3d(0.1, 0.0, 0.0), 0.1);
  r.states[0].usable = false;               // INITIALIZING
  r.states[1].utime += 1;                   // no truth at its time
  r.states[2].P = Eigen::Matrix3d::Zero();  // its error is scored, but no NEES under a singular covariance
  r.states[2].P(0, 0) = 1.0;
  const FlightScore s = score_flight(r, Eigen::Vector3d(1.0, 0.0, 1.0), 0.3, {});
  EXPECT_EQ(s.states_scored, 9);
  EXPECT_NEAR(s.error_mean_m, 0.1, 1e-12);
  EXPECT_NEAR(s.nees_mean, 1.0, 1e-9);  // the other eight: (0.1 / 0.1)^2
  EXPECT_THROW(score_flight(FlightRecord{}, Eigen::Vector3d::Zero(), 0.3, {}), std::invalid_argument);
}

// STATE's covariance at each planned node: where the truth came nearest it, in path order.
TEST(FlightScore, FlownCovarianceIsTakenWhereTheTruthPassedEachNode) {
  FlightRecord r = straight_flight(5.0, Eigen::Vector3d::Zero(), 0.1);
  for (size_t i = 0; i < r.states.size(); ++i) r.states[i].P = static_cast<double>(i) * Eigen::Matrix3d::Identity();
  PlannedPath plan;
  plan.nodes = {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(2.0, 0.2, 1), Eigen::Vector3d(5, 0, 1)};
  const FlightScore s = score_flight(r, Eigen::Vector3d(5.0, 0.0, 1.0), 0.3, plan);
  ASSERT_EQ(s.flown_trace.size(), 3u);
  EXPECT_NEAR(s.flown_trace[0], 0.0, 1e-12);
  EXPECT_NEAR(s.flown_trace[1], 3.0 * 20, 1e-12);  // x = 2.0 is the 21st sample
  EXPECT_NEAR(s.flown_trace[2], 3.0 * 50, 1e-12);
}

TEST(FlightLog, TheLastGraphCountsEvenWhenOnlyKeyframesWereAdded) {
  // SLAM's revision counts optimisations: keyframes added between two keep the revision, and
  // the flight's keyframes are the latest graph's, not the first of its revision.
  test::TempDir dir;
  const std::string path = (dir / "flight.lcmlog").string();
  {
    transport::LogWriter log(path);
    kestrel::ground_truth_t truth{};
    truth.utime = 1'000'000;
    truth.T_world_frame.orientation[0] = 1.0;
    log.write_message(channel::kGroundTruth, truth.utime, truth);
    const std::vector<std::pair<int64_t, int>> graphs = {{0, 1}, {0, 2}, {1, 5}, {1, 8}, {0, 3}};
    int64_t utime = 1'000'000;
    for (const auto& [revision, keyframes] : graphs) {
      kestrel::slam_graph_t g{};
      g.utime = utime += 100'000;
      g.revision = revision;
      g.num_keyframes = keyframes;
      g.keyframes.resize(static_cast<size_t>(keyframes));
      log.write_message(channel::kSlamGraph, g.utime, g);
    }
    log.close();
  }
  // The stale revision-0 graph at the end is a duplicate from before the optimisation.
  EXPECT_EQ(read_flight_log(path).keyframes, 8);
}

}  // namespace
}  // namespace kestrel::flights
