#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/trajectory.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

TEST(Trajectory, TumFileRoundTrip) {
  test::TempDir dir;
  Trajectory t;
  for (int i = 0; i < 10; ++i) {
    t.push_back(1305031229528784 + i * 33333,
                se3::make(so3::exp(Eigen::Vector3d(0.1 * i, -0.05 * i, 0.2)),
                          Eigen::Vector3d(i * 0.1, -i * 0.2, 1.0 + i)));
  }
  write_tum_trajectory(dir / "t.txt", t);
  const Trajectory back = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(back.poses()[i].utime, t.poses()[i].utime);
    EXPECT_LT((back.poses()[i].T.matrix() - t.poses()[i].T.matrix()).norm(), 1e-7);
  }
}

TEST(Trajectory, QuaternionOrderIsXyzwInTumFiles) {
  test::TempDir dir;
  // 90 degrees about z: q = (x, y, z, w) = (0, 0, sin 45, cos 45).
  write_file(dir / "t.txt", "# comment\n\n1.0 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n");
  const Trajectory t = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_TRUE((t.poses()[0].T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(Trajectory, InterpolatesOnlyWithinTheGap) {
  Trajectory t;
  t.push_back(0, se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 0)));
  t.push_back(10000, se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 0, 0)));
  t.push_back(200000, se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(2, 0, 0)));
  ASSERT_TRUE(t.at(2500, 20000).has_value());
  EXPECT_NEAR(t.at(2500, 20000)->translation().x(), 0.25, 1e-12);
  EXPECT_TRUE(t.at(10000, 0).has_value());          // exact sample
  EXPECT_FALSE(t.at(100000, 20000).has_value());    // inside a 190 ms gap
  EXPECT_FALSE(t.at(-1, 20000).has_value());        // before the first sample
  EXPECT_FALSE(t.at(200001, 20000).has_value());    // after the last
}

struct BadFile {
  const char* text;
  const char* expect;  // part of the error message
};

TEST(Trajectory, BadFilesNameTheFileAndLine) {
  test::TempDir dir;
  const BadFile cases[] = {
      {"1.0 1 2 3 0 0 0 1\n1.0 1 2 3 0 0 0 1\n", ":2: timestamp 1.0 is not after"},
      {"1.0 1 2 3 0 0 0\n", ":1: expected 'timestamp tx ty tz qx qy qz qw'"},
      {"# h\nabc 1 2 3 0 0 0 1\n", ":2: bad timestamp 'abc'"},
      {"1.0 nan 2 3 0 0 0 1\n", ":1: non-finite value"},
      {"1.0 1 2 3 0 0 0 2\n", ":1: quaternion is not of unit length"},
  };
  for (const auto& c : cases) {
    write_file(dir / "bad.txt", c.text);
    try {
      read_tum_trajectory(dir / "bad.txt");
      ADD_FAILURE() << "no error for: " << c.text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find((dir / "bad.txt").string() + c.expect), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(read_tum_trajectory(dir / "missing.txt"), InputError);
}

}  // namespace
}  // namespace kestrel
