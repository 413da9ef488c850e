// place_frame (sequence_run.h): how the offline run places a frame between keyframes by the
// optimised graph's corrections of the odometry.

#include <gtest/gtest.h>

#include "common/geometry/se3.h"
#include "slam/sequence_run.h"

namespace kestrel::slam {
namespace {

Eigen::Isometry3d pose(double x, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << x, 0.2, -0.1;
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// Keyframes at 1, 2 and 3 s: the graph moved the second by 4 cm and 0.02 rad and the third by
// 8 cm; the third starts a new odometry segment (a break).
std::vector<KeyframeCorrection> corrections() {
  return {{1000000, Eigen::Isometry3d::Identity(), false},
          {2000000, pose(0.04, 0.02), true},
          {3000000, pose(0.08, 0.0), false}};
}

TEST(PlaceFrame, SpreadsTheCorrectionBetweenKeyframesOfOneSegment) {
  const auto k = corrections();
  const Eigen::Isometry3d T_odom = pose(1.5, 0.3);
  // At a keyframe's own time its correction; a quarter of the way the correction a quarter on.
  EXPECT_TRUE(place_frame(k, 0, 1000000, T_odom).isApprox(T_odom, 1e-12));
  const Eigen::Isometry3d quarter = place_frame(k, 0, 1250000, T_odom);
  const Eigen::Isometry3d T_world_odom = quarter * T_odom.inverse();
  EXPECT_NEAR(T_world_odom.translation().x(), 0.01, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(T_world_odom.linear()).angle(), 0.005, 1e-12);
  // Continuous in time: just before the next keyframe it nearly has that keyframe's correction.
  EXPECT_LT(se3::translation_distance(place_frame(k, 0, 1999999, T_odom), k[1].T_world_odom * T_odom), 1e-6);
}

TEST(PlaceFrame, KeepsTheKeyframesOwnCorrectionBeforeABreakAndAfterTheNewest) {
  const auto k = corrections();
  const Eigen::Isometry3d T_odom = pose(-0.3, 1.0);
  EXPECT_TRUE(place_frame(k, 1, 2500000, T_odom).isApprox(k[1].T_world_odom * T_odom, 1e-12)) << "before a break";
  EXPECT_TRUE(place_frame(k, 2, 3500000, T_odom).isApprox(k[2].T_world_odom * T_odom, 1e-12)) << "after the newest";
  EXPECT_THROW(place_frame(k, 3, 3500000, T_odom), std::out_of_range);
}

}  // namespace
}  // namespace kestrel::slam
