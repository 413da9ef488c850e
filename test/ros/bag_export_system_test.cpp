// bag-export on what the system produced: a 3 s closed-loop flight in the sim's room, the VO and
// the estimator in lock-step (as sim_tool_test flies it), recorded, exported, and read back with
// librosbag: every STATE is an Odometry with the same stamp and pose, every GROUND_TRUTH a
// PoseStamped, and /kestrel/vo holds the trajectory `kestrel eval` makes of VO_UPDATE.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2_msgs/TFMessage.h>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/state_t.hpp"
#include "ros/ros_convert.h"
#include "test/support/test_support.h"
#include "tools/eval/log_input.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

TEST(BagExportSystem, AFlightsStateVoAndTruthAreInTheBag) {
  for (const char* t : {"sim", "vo", "estimator", "bag-export"})
    if (!fs::exists(test::tool(t))) KESTREL_SKIP_ENVIRONMENT() << test::tool(t) << " is not built";
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here";
  test::TempDir dir;
  const std::string rec = (dir / "flight.lcmlog").string();
  const std::string script =
      "export LCM_DEFAULT_URL=" + test::quoted(transport::kDefaultLcmUrl) + " && '" + test::tool("vo").string() +
      "' -q & V=$!; '" + test::tool("estimator").string() + "' -q --init-position 8,3.5,1.3 & E=$!; '" +
      test::tool("sim").string() + "' --world room --flight vehicle --duration 3 --lockstep 20 --expect vo,estimator --record " +
      test::quoted(rec) + "; S=$?; kill -INT $V $E; wait $V $E; exit $S";
  const auto flown = test::run_isolated(script, 240.0);
  ASSERT_EQ(flown.exit_code, 0) << flown.err;

  const fs::path bag_path = dir / "flight.bag";
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = test::run({test::tool("bag-export").string(), rec, "--bag", bag_path.string()}, 120.0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::cout << r.out << "(export run: " << seconds << " s, log " << fs::file_size(rec) << " bytes, bag "
            << fs::file_size(bag_path) << " bytes)\n";

  const auto states = transport::read_messages<kestrel::state_t>(rec, channel::kState);
  const auto truth = transport::read_messages<kestrel::ground_truth_t>(rec, channel::kGroundTruth);
  ASSERT_GT(states.size(), 100u);
  ASSERT_GT(truth.size(), 100u);
  rosbag::Bag bag(bag_path.string(), rosbag::bagmode::Read);

  size_t i = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/odom"))) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(o);
    ASSERT_LT(i, states.size());
    const kestrel::state_t& s = states[i++];
    ASSERT_EQ(o->header.stamp, ros1::to_ros_time(s.utime));
    const double p[3] = {o->pose.pose.position.x, o->pose.pose.position.y, o->pose.pose.position.z};
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(p[k], s.T_world_body.position[k], 1e-9);
    const auto& q = o->pose.pose.orientation;
    // The same rotation (a quaternion and its negation are one).
    const double dot = q.w * s.T_world_body.orientation[0] + q.x * s.T_world_body.orientation[1] +
                       q.y * s.T_world_body.orientation[2] + q.z * s.T_world_body.orientation[3];
    ASSERT_NEAR(std::abs(dot), 1.0, 1e-9);
    // The covariance's position block is the state's dp block as it is.
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) ASSERT_EQ(o->pose.covariance[static_cast<size_t>(a * 6 + b)], s.covariance[a][b]);
  }
  EXPECT_EQ(i, states.size());
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/tf")).size(), states.size());
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/tf_static")).size(), 1u);
  EXPECT_EQ(rosbag::View(bag, rosbag::TopicQuery("/kestrel/ground_truth")).size(), truth.size());

  // /kestrel/vo is eval's VO trajectory, pose for pose.
  const eval::TrajectoryInput vo = eval::read_log_input(rec, {channel::kVoUpdate});
  ASSERT_GT(vo.trajectory.size(), 50u);
  size_t j = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/kestrel/vo"))) {
    const auto o = m.instantiate<nav_msgs::Odometry>();
    ASSERT_TRUE(o);
    ASSERT_LT(j, vo.trajectory.size());
    const StampedPose& want = vo.trajectory.poses()[j++];
    ASSERT_EQ(o->header.stamp, ros1::to_ros_time(want.utime));
    ASSERT_NEAR(o->pose.pose.position.x, want.T.translation().x(), 1e-9);
    ASSERT_NEAR(o->pose.pose.position.y, want.T.translation().y(), 1e-9);
    ASSERT_NEAR(o->pose.pose.position.z, want.T.translation().z(), 1e-9);
  }
  EXPECT_EQ(j, vo.trajectory.size());
}

}  // namespace
}  // namespace kestrel
