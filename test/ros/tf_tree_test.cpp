// The tf tree bag-import and ros-bridge read (ros/tf_tree.h), on hand-worked trees.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/error.h"
#include "ros/tf_tree.h"
#include "test/ros/bag_writer.h"

namespace kestrel {
namespace {

Eigen::Isometry3d pose(double x, double y, double z, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// A motion capture world -> rig at 100 Hz (the rig moving along x, 1 m/s), the camera mounted
// on the rig 10 cm up and turned 90 degrees, published every 3rd rig transform.
ros1::TfTree mocap_tree(int64_t keep_us = 0) {
  ros1::TfTree tree(keep_us);
  for (int i = 0; i < 30; ++i) {
    const int64_t t = 1'000'000 + 10'000 * i;
    tf2_msgs::TFMessage m;
    m.transforms.push_back(test::transform(t, "/world", "/rig", pose(0.01 * i, 0, 1)));
    if (i % 3 == 1) m.transforms.push_back(test::transform(t, "rig", "camera", pose(0, 0, 0.1, M_PI / 2)));
    tree.add(m, "test: /tf");
  }
  return tree;
}

TEST(TfTree, TheGroundTruthComposesTheChainAtEachTransformOfItsBusiestEdge) {
  const ros1::TfTree tree = mocap_tree();
  std::string why;
  const std::vector<std::string> chain = tree.chain("world", "camera", why);
  EXPECT_EQ(chain, (std::vector<std::string>{"camera", "rig"}));
  EXPECT_EQ(tree.busiest(chain), "rig");
  EXPECT_EQ(tree.path(chain), "world -> rig -> camera");
  const std::vector<ros1::TimedPose> poses = tree.poses("world", "camera", "/tf", why);
  EXPECT_EQ(why, "/tf: world -> rig -> camera");
  ASSERT_EQ(poses.size(), 30u);
  // The mount's first transform (at i = 1) stands for the times before it too.
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(poses[i].utime, 1'000'000 + 10'000 * static_cast<int64_t>(i));
    EXPECT_TRUE(poses[i].T.isApprox(pose(0.01 * static_cast<double>(i), 0, 1.1, M_PI / 2), 1e-12)) << i;
  }
  // Between two transforms: the latest before.
  EXPECT_TRUE(tree.along(chain, 1'015'000).isApprox(pose(0.01, 0, 1.1, M_PI / 2), 1e-12));
}

TEST(TfTree, TheRotationBetweenTwoFramesIsTheirMountsWhenTheTreeJoinsThem) {
  ros1::TfTree tree;
  ASSERT_TRUE(tree.add("camera_link", "color_optical", 0, pose(0.01, 0, 0, M_PI / 2)));
  ASSERT_TRUE(tree.add("camera_link", "imu", 0, pose(0, 0.02, 0)));
  const auto R = tree.rotation("color_optical", "imu", 5);
  ASSERT_TRUE(R.has_value());
  // The IMU's x axis is the camera's -y.
  EXPECT_TRUE((*R * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitY(), 1e-15));
  EXPECT_FALSE(tree.rotation("color_optical", "elsewhere", 5).has_value());
  EXPECT_TRUE(tree.rotation("imu", "imu", 5)->isIdentity());
}

TEST(TfTree, ASecondParentAndABadTransformChangeNothing) {
  ros1::TfTree tree;
  ASSERT_TRUE(tree.add("world", "rig", 0, pose(1, 0, 0)));
  EXPECT_FALSE(tree.add("elsewhere", "rig", 1, pose(5, 0, 0)));
  EXPECT_EQ(tree.second_parents(), 1);
  EXPECT_EQ(tree.in_root("rig", 1).first, "world");
  EXPECT_TRUE(tree.in_root("rig", 1).second.isApprox(pose(1, 0, 0)));
  // One transform of the message is not a rotation: none of it is taken.
  tf2_msgs::TFMessage m;
  m.transforms.push_back(test::transform(2, "world", "rig", pose(2, 0, 0)));
  m.transforms.push_back(test::transform(2, "rig", "camera", pose(0, 0, 0)));
  m.transforms.back().transform.rotation.w = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tree.add(m, "test: /tf"), InputError);
  EXPECT_TRUE(tree.in_root("rig", 3).second.isApprox(pose(1, 0, 0)));
  std::string why;
  EXPECT_TRUE(tree.chain("world", "camera", why).empty());
  EXPECT_EQ(why, "no chain of transforms from 'world' to 'camera'");
  EXPECT_TRUE(tree.poses("world", "world", "/tf", why).empty());
  EXPECT_EQ(why, "none: the world and camera frames are the same ('world')");
}

TEST(TfTree, ALiveTreeKeepsItsLastSecondsAndAnswersInThemAsWithItsWholeHistory) {
  const ros1::TfTree whole = mocap_tree();
  const ros1::TfTree live = mocap_tree(50'000);  // 50 ms of 290
  std::string why;
  const auto chain = whole.chain("world", "camera", why);
  for (int64_t t = 1'240'000; t <= 1'300'000; t += 5'000)
    EXPECT_TRUE(live.along(chain, t).isApprox(whole.along(chain, t), 0.0)) << t;
  // What was let go: the rig's transforms before 240 ms but the one before them; the
  // counts stay whole (the busiest edge is still the motion capture's).
  EXPECT_TRUE(live.along(chain, 1'000'000).isApprox(pose(0.23, 0, 1.1, M_PI / 2), 1e-12));
  EXPECT_EQ(live.busiest(chain), "rig");
}

}  // namespace
}  // namespace kestrel
