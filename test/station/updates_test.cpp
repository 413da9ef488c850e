// Messages as the page's updates: poses, covariance ellipsoids, plans, the SLAM graph, and
// the bounded histories (paths, rates, health).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "common/error.h"
#include "common/transport/convert.h"
#include "station/updates.h"

namespace kestrel::station {
namespace {

kestrel::state_t state_at(const Eigen::Vector3d& p, double yaw, const Eigen::Matrix3d& position_cov) {
  kestrel::state_t m{};
  m.utime = 1'000'000;
  m.status = kestrel::state_t::STATUS_OK;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = p;
  m.T_world_body = transport::to_message(T);
  m.cov_dim = 15;
  m.covariance.assign(15, std::vector<double>(15, 0.0));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.covariance[static_cast<size_t>(r)][static_cast<size_t>(c)] = position_cov(r, c);
  return m;
}

Eigen::Vector3d vec(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

TEST(StationUpdates, StateGivesThePoseAndTheEllipsoidOfItsPositionCovariance) {
  // An ellipsoid with semi-axes 0.3, 0.2, 0.1 m turned 30 degrees about z: the update's axes
  // and rotation must give the covariance back.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d cov = R * Eigen::Vector3d(0.09, 0.04, 0.01).asDiagonal() * R.transpose();
  const nlohmann::json u = state_update(state_at({1.0, -2.0, 1.5}, 0.7, cov), "STATE");
  EXPECT_EQ(u["kind"], "state");
  EXPECT_TRUE(vec(u["p"]).isApprox(Eigen::Vector3d(1.0, -2.0, 1.5)));
  EXPECT_NEAR(u["yaw"].get<double>(), 0.7, 1e-12);
  ASSERT_TRUE(u.contains("cov"));
  const Eigen::Vector3d radii = vec(u["cov"]["radii"]);
  const auto& q = u["cov"]["q"];
  const Eigen::Matrix3d axes =
      Eigen::Quaterniond(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>()).toRotationMatrix();
  const Eigen::Matrix3d back = axes * radii.cwiseProduct(radii).asDiagonal() * axes.transpose();
  EXPECT_TRUE(back.isApprox(cov, 1e-9)) << back;
  EXPECT_NEAR(radii.maxCoeff(), 0.3, 1e-9);
  EXPECT_NEAR(radii.minCoeff(), 0.1, 1e-9);
}

TEST(StationUpdates, AnUnusableCovarianceIsLeftOutAndABadPoseRefused) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 0.01;
  cov(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(state_update(state_at({0, 0, 1}, 0, cov), "STATE").contains("cov"));
  kestrel::state_t wrong_size = state_at({0, 0, 1}, 0, Eigen::Matrix3d::Identity());
  wrong_size.cov_dim = 16;  // disagrees with the 15 rows
  EXPECT_FALSE(state_update(wrong_size, "STATE").contains("cov"));
  kestrel::state_t nan_pose = state_at({0, 0, 1}, 0, Eigen::Matrix3d::Identity());
  nan_pose.T_world_body.position[1] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(state_update(nan_pose, "STATE"), InputError);
  kestrel::state_t not_rotation = state_at({0, 0, 1}, 0, Eigen::Matrix3d::Identity());
  not_rotation.T_world_body.orientation[0] = 3.0;  // far from unit length
  EXPECT_THROW(state_update(not_rotation, "STATE"), InputError);
}

TEST(StationUpdates, APlanCarriesItsWaypointsAndTheSigmaOfItsTrace) {
  kestrel::plan_t p{};
  p.request_id = 12;
  p.status = kestrel::plan_t::STATUS_OK;
  p.num_waypoints = 2;
  p.waypoints = {{0, 0, 1, 0}, {2, 1, 1, 0.5}};
  p.covariance_trace = {0.04, 0.16};  // tr / 4 = 0.01, 0.04: sigma 0.1, 0.2
  p.length = std::sqrt(5.0);
  const nlohmann::json u = plan_update(p, "PLAN");
  EXPECT_EQ(u["status_name"], "OK");
  EXPECT_EQ(u["waypoints"].size(), 2u);
  EXPECT_NEAR(u["sigma"][0].get<double>(), 0.1, 1e-12);
  EXPECT_NEAR(u["sigma"][1].get<double>(), 0.2, 1e-12);
  p.num_waypoints = 3;
  EXPECT_THROW(plan_update(p, "PLAN"), InputError);
  p.num_waypoints = 2;
  p.waypoints[1][2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(plan_update(p, "PLAN"), InputError);
}

TEST(StationUpdates, APlanWithItsCovarianceCarriesEachWaypointsHorizontalEllipse) {
  kestrel::plan_t p{};
  p.utime = 5;
  p.request_id = 12;
  p.num_waypoints = 2;
  p.waypoints = {{0, 0, 1, 0}, {2, 1, 1, 0.5}};
  p.covariance_trace = {5.0, 2.0};
  kestrel::plan_covariance_t c{};
  c.utime = 5;
  c.request_id = 12;
  c.num_waypoints = 2;
  c.covariance.resize(2);
  // Waypoint 0: var x 4, var y 1 (uncorrelated): semi-axes 2 and 1 along x. Waypoint 1: the
  // same turned by 30 degrees, R diag(4, 1) R^T = [[3.25, 1.299], [1.299, 1.75]].
  c.covariance[0] = {4, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  const double a = M_PI / 6, ca = std::cos(a), sa = std::sin(a);
  const double xx = 4 * ca * ca + sa * sa, yy = 4 * sa * sa + ca * ca, xy = 3 * ca * sa;
  c.covariance[1] = {xx, xy, 0, 0, xy, yy, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  const nlohmann::json u = plan_update(p, "PLAN_COVARIANCE", &c);
  ASSERT_EQ(u["ellipses"].size(), 2u);
  EXPECT_NEAR(u["ellipses"][0][0].get<double>(), 2.0, 1e-12);
  EXPECT_NEAR(u["ellipses"][0][1].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(u["ellipses"][0][2].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(u["ellipses"][1][0].get<double>(), 2.0, 1e-12);
  EXPECT_NEAR(u["ellipses"][1][1].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(u["ellipses"][1][2].get<double>(), a, 1e-12);
  EXPECT_FALSE(plan_update(p, "PLAN").contains("ellipses"));
  // Another plan's, a count that disagrees, a value that is not finite: refused.
  c.request_id = 13;
  EXPECT_THROW(plan_update(p, "PLAN_COVARIANCE", &c), InputError);
  c.request_id = 12;
  c.num_waypoints = 1;
  EXPECT_THROW(plan_update(p, "PLAN_COVARIANCE", &c), InputError);
  c.num_waypoints = 2;
  c.covariance[1][5] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(plan_update(p, "PLAN_COVARIANCE", &c), InputError);
}

TEST(StationUpdates, TheGraphNamesEdgesByKeyframeIndex) {
  kestrel::slam_graph_t g{};
  g.revision = 4;
  for (int i = 0; i < 3; ++i) {
    kestrel::slam_keyframe_t kf{};
    kf.id = 100 + i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i, 0, 1);
    kf.T_world_camera = transport::to_message(T);
    kf.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
    g.keyframes.push_back(kf);
  }
  g.num_keyframes = 3;
  const auto edge = [](int64_t a, int64_t b, int8_t kind) {
    kestrel::slam_edge_t e{};
    e.from_id = a;
    e.to_id = b;
    e.kind = kind;
    e.T_from_to = transport::to_message(Eigen::Isometry3d::Identity());
    return e;
  };
  g.edges = {edge(100, 101, kestrel::slam_edge_t::KIND_ODOMETRY), edge(101, 102, kestrel::slam_edge_t::KIND_ODOMETRY),
             edge(102, 100, kestrel::slam_edge_t::KIND_LOOP_CLOSURE), edge(102, 999, kestrel::slam_edge_t::KIND_LOOP_CLOSURE)};
  g.num_edges = 4;
  const nlohmann::json u = graph_update(g, "SLAM_GRAPH");
  EXPECT_EQ(u["keyframes"].size(), 3u);
  EXPECT_TRUE(vec(u["keyframes"][2]).isApprox(Eigen::Vector3d(2, 0, 1)));
  EXPECT_EQ(u["odometry"], nlohmann::json::parse("[[0,1],[1,2]]"));
  EXPECT_EQ(u["loops"], nlohmann::json::parse("[[2,0]]"));  // the edge to an unknown keyframe is left out
  g.num_edges = 5;
  EXPECT_THROW(graph_update(g, "SLAM_GRAPH"), InputError);
}

TEST(StationUpdates, APathKeepsAPointPerStepAndStaysBounded) {
  PathTrace path(0.1, 8);
  EXPECT_TRUE(path.add({0, 0, 0}));
  EXPECT_FALSE(path.add({0.05, 0, 0}));  // closer than a step
  EXPECT_TRUE(path.add({0.1, 0, 0}));
  EXPECT_FALSE(path.add({std::nan(""), 0, 0}));
  for (int i = 2; i < 100; ++i) EXPECT_TRUE(path.add({0.2 * i, 0, 0}));
  EXPECT_LE(path.points().size(), 8u);
  EXPECT_EQ(path.points().front(), Eigen::Vector3d(0, 0, 0));
  EXPECT_NEAR(path.points().back().x(), 0.2 * 99, 1e-9);  // the newest is always kept
}

TEST(StationUpdates, RatesAreCountsOverTheInterval) {
  ChannelRates rates;
  rates.snapshot(10.0);  // starts the interval
  for (int i = 0; i < 10; ++i) rates.on_message("STATE", 100);
  rates.on_message("PLAN", 50);
  const nlohmann::json u = rates.snapshot(12.0);
  ASSERT_EQ(u["channels"].size(), 2u);
  EXPECT_EQ(u["channels"][1]["channel"], "STATE");
  EXPECT_DOUBLE_EQ(u["channels"][1]["hz"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(u["channels"][1]["bytes_per_s"].get<double>(), 500.0);
  EXPECT_DOUBLE_EQ(u["channels"][0]["hz"].get<double>(), 0.5);
  // Silent for one interval: shown at 0 Hz; for two: gone.
  EXPECT_DOUBLE_EQ(rates.snapshot(13.0)["channels"][1]["hz"].get<double>(), 0.0);
  EXPECT_EQ(rates.snapshot(14.0)["channels"].size(), 0u);
  // Many names: bounded.
  for (int i = 0; i < 500; ++i) rates.on_message("C" + std::to_string(i), 1);
  EXPECT_EQ(rates.snapshot(15.0)["channels"].size(), ChannelRates::kMaxChannels + 1);
}

TEST(StationUpdates, TheHealthTableListsEveryProcessOnceByName) {
  HealthTable table;
  kestrel::process_status_t s{};
  s.name = "mapper";
  s.state = kestrel::process_status_t::STATE_RUNNING;
  table.on_status(s, 1.0);
  s.name = "estimator";
  s.state = kestrel::process_status_t::STATE_DEGRADED;
  s.message = "no VO";
  table.on_status(s, 2.0);
  s.name = "mapper";
  table.on_status(s, 3.0);
  EXPECT_EQ(table.names(), (std::vector<std::string>{"estimator", "mapper"}));
  const nlohmann::json u = table.to_json(4.0);
  EXPECT_EQ(u["processes"][0]["state_name"], "DEGRADED");
  EXPECT_EQ(u["processes"][0]["message"], "no VO");
  EXPECT_DOUBLE_EQ(u["processes"][1]["age_s"].get<double>(), 1.0);
}

}  // namespace
}  // namespace kestrel::station

namespace kestrel::station {
namespace {

TEST(StationUpdates, APathIsSentInMillimetres) {
  PathTrace path(0.01, 10);
  path.add({1.23456, -0.25049, 2.0});
  const nlohmann::json u = path.to_json("path");
  EXPECT_DOUBLE_EQ(u["points"][0][0].get<double>(), 1.235);
  EXPECT_DOUBLE_EQ(u["points"][0][1].get<double>(), -0.25);
  EXPECT_EQ(path.added(), 1);
}

}  // namespace
}  // namespace kestrel::station
