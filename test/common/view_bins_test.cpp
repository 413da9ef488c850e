// The thinning policy the mapper's stored scans and SLAM's matchable keyframes share
// (common/geometry/view_bins.h), on hand-placed views: the fullest bin gives its oldest view
// first, a place seen once keeps its only view, the kept id is never chosen.

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/geometry/view_bins.h"
#include "common/numbers.h"

namespace kestrel {
namespace {

// A camera at (x, y, 1) looking horizontally along yaw (optical z forward, y down).
Eigen::Isometry3d view(double x, double y, double yaw_rad) {
  Eigen::Matrix3d R_world_optical;
  R_world_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // optical axis along world x
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_world_optical;
  T.translation() = Eigen::Vector3d(x, y, 1.0);
  return T;
}

TEST(ViewBins, TheFullestBinGivesItsOldestViewFirst) {
  ViewBins bins(0.5, 30.0);
  bins.insert(1, view(0.1, 0.1, 0.0));   // place A, looking along x
  bins.insert(2, view(3.1, 0.1, 0.0));   // place B: seen once
  bins.insert(3, view(0.2, 0.2, 0.05));  // A again, a similar view
  bins.insert(4, view(0.3, 0.1, 0.1));   // and again
  bins.insert(5, view(0.2, 0.1, kPi));   // A looking the other way: another bin
  EXPECT_EQ(bins.size(), 5u);
  EXPECT_EQ(bins.first_to_thin(), 1);
  bins.erase(1);
  EXPECT_EQ(bins.first_to_thin(), 3);
  bins.erase(3);
  // Each bin holds one view now: equally full, the oldest view goes first.
  EXPECT_EQ(bins.first_to_thin(), 2);
  // A second view of B makes B the fullest.
  bins.insert(6, view(3.2, 0.2, 0.05));
  EXPECT_EQ(bins.first_to_thin(), 2) << "B is the fullest bin now";
  EXPECT_EQ(bins.first_to_thin(2), 6) << "the kept id is never chosen";
}

TEST(ViewBins, AViewThatMovesIsTheNewestOfItsNewBin) {
  ViewBins bins(0.5, 30.0);
  bins.insert(1, view(0.1, 0.1, 0.0));
  bins.insert(2, view(3.1, 0.1, 0.0));
  bins.insert(3, view(3.2, 0.1, 0.0));
  bins.insert(1, view(3.3, 0.1, 0.0));  // a loop closure moved keyframe 1 to B
  EXPECT_EQ(bins.size(), 3u);
  EXPECT_EQ(bins.first_to_thin(), 2);
  bins.erase(2);
  EXPECT_EQ(bins.first_to_thin(), 3);
  bins.erase(3);
  EXPECT_EQ(bins.first_to_thin(), 1);
  EXPECT_FALSE(bins.first_to_thin(1)) << "only the kept id is left";
  bins.erase(42);  // absent: nothing
  EXPECT_EQ(bins.size(), 1u);
}

TEST(ViewBins, RefusesBinsThatAreNotSizes) {
  EXPECT_THROW(ViewBins(0.0, 30.0), std::invalid_argument);
  EXPECT_THROW(ViewBins(std::nan(""), 30.0), std::invalid_argument);
  EXPECT_THROW(ViewBins(0.5, 0.0), std::invalid_argument);
  EXPECT_THROW(ViewBins(0.5, 181.0), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel
