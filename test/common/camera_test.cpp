// PinholeCamera: the lens model's forward map on hand-computed cases, and its validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/camera.h"
#include "common/error.h"
#include "test/support/numerical.h"

namespace kestrel {
namespace {

PinholeCamera simple_camera() {
  PinholeCamera c = PinholeCamera::vga(500.0, 500.0, 0.0, 0.0);
  return c;
}

TEST(PinholeCamera, WithoutDistortionDistortIsTheIdentityExactly) {
  const PinholeCamera c = PinholeCamera::vga(525.0, 525.0, 319.5, 239.5);
  EXPECT_FALSE(c.distorted());
  for (const double u : {-3.1, 0.0, 100.25, 639.7}) {
    for (const double v : {-0.3, 17.125, 479.9}) {
      EXPECT_EQ(c.distort(u, v), Eigen::Vector2d(u, v));
    }
  }
}

TEST(PinholeCamera, DistortMatchesHandComputedBrownConrady) {
  PinholeCamera c = simple_camera();
  // Radial only, k1 = 0.1: the ideal pixel (250, 0) is x = 0.5, r^2 = 0.25, radial 1.025.
  c.distortion = {0.1, 0.0, 0.0, 0.0, 0.0};
  EXPECT_TRUE(c.distorted());
  Eigen::Vector2d raw = c.distort(250.0, 0.0);
  EXPECT_NEAR(raw.x(), 256.25, 1e-12);
  EXPECT_NEAR(raw.y(), 0.0, 1e-12);
  // k2 and k3 at r^2 = 0.25 + 0.25 = 0.5 (pixel (250, 250)): radial 1 + 0.5 (0.1 + 0.5 (0.2 + 0.5 0.4)) = 1.15.
  c.distortion = {0.1, 0.2, 0.0, 0.0, 0.4};
  raw = c.distort(250.0, 250.0);
  EXPECT_NEAR(raw.x(), 287.5, 1e-12);
  EXPECT_NEAR(raw.y(), 287.5, 1e-12);
  // Tangential only at (250, 0): x' = x + p2 (r^2 + 2 x^2) = 0.5 + 0.02 * 0.75, y' = p1 r^2 = 0.01 * 0.25.
  c.distortion = {0.0, 0.0, 0.01, 0.02, 0.0};
  raw = c.distort(250.0, 0.0);
  EXPECT_NEAR(raw.x(), 257.5, 1e-12);
  EXPECT_NEAR(raw.y(), 1.25, 1e-12);
}

TEST(PinholeCamera, NormalisedDistortionJacobianMatchesCentralDifferences) {
  PinholeCamera c = simple_camera();
  c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // freiburg1's
  for (const double x : {-0.6, -0.1, 0.0, 0.35}) {
    for (const double y : {-0.45, 0.05, 0.4}) {
      Eigen::Matrix2d J;
      const Eigen::Vector2d d = c.distort_normalized(x, y, &J);
      EXPECT_EQ(d, c.distort_normalized(x, y));  // the Jacobian changes nothing
      const Eigen::Matrix2d numeric = test::numerical_jacobian<2>(
          [&](const Eigen::Vector2d& e) -> Eigen::Vector2d { return c.distort_normalized(x + e.x(), y + e.y()); });
      EXPECT_NEAR((J - numeric).cwiseAbs().maxCoeff(), 0.0, 1e-8) << x << ", " << y;
    }
  }
}

TEST(PinholeCamera, NonFiniteDistortionIsAnInputError) {
  PinholeCamera c = simple_camera();
  c.validate("camera");
  c.distortion[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(c.validate("camera"), InputError);
  c.distortion[1] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(c.validate("camera"), InputError);
}

}  // namespace
}  // namespace kestrel
