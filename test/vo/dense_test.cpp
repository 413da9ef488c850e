// The dense geometric term with known answers: the coarse depth grid of a fronto-parallel wall
// (points on the wall, normals facing the camera), the forward distortion against the lens's
// inverse table, and the point-to-plane refinement alone recovering a known motion between two
// rendered views of the synthetic room.

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "common/geometry/se3.h"
#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "test/vo/synthetic_scene.h"
#include "vo/dense_depth.h"
#include "vo/motion_refinement.h"

namespace kestrel::vo {
namespace {

TEST(DenseDepth, WallGivesItsPointsAndNormal) {
  const PinholeCamera cam = test::test_camera();
  sensors::Lens lens;
  lens.reset(cam, false);
  const cv::Mat depth(cam.height, cam.width, CV_16UC1, cv::Scalar(1500));  // a wall at 1.5 m
  DenseDepth grid;
  build_dense_depth(depth, lens, DepthOptions{}, 3, grid);
  ASSERT_EQ(grid.width, cam.width / 8);
  ASSERT_EQ(grid.height, cam.height / 8);
  int normals = 0;
  for (int y = 0; y < grid.height; ++y) {
    for (int x = 0; x < grid.width; ++x) {
      const size_t i = static_cast<size_t>(y * grid.width + x);
      const Eigen::Vector3f& P = grid.points[i];
      ASSERT_NEAR(P.z(), 1.5f, 1e-6f);
      // On the ray through the block's centre (raw pixel 8x + 3.5).
      EXPECT_NEAR(P.x(), 1.5 * (8 * x + 3.5 - cam.cx) / cam.fx, 1e-5);
      EXPECT_NEAR(P.y(), 1.5 * (8 * y + 3.5 - cam.cy) / cam.fy, 1e-5);
      const Eigen::Vector3f& n = grid.normals[i];
      const bool border = x == 0 || y == 0 || x + 1 == grid.width || y + 1 == grid.height;
      if (border) {
        EXPECT_EQ(n.squaredNorm(), 0.0f);
      } else {
        EXPECT_NEAR(n.z(), -1.0f, 1e-5f);
        ++normals;
      }
    }
  }
  EXPECT_EQ(normals, (grid.width - 2) * (grid.height - 2));
}

TEST(DenseDepth, DepthEdgeHasNoNormal) {
  const PinholeCamera cam = test::test_camera();
  sensors::Lens lens;
  lens.reset(cam, false);
  cv::Mat depth(cam.height, cam.width, CV_16UC1, cv::Scalar(1500));
  depth.colRange(0, 320).setTo(cv::Scalar(1000));  // a step at column 320 (a block boundary)
  DenseDepth grid;
  build_dense_depth(depth, lens, DepthOptions{}, 3, grid);
  const int y = grid.height / 2;
  EXPECT_EQ(grid.normals[static_cast<size_t>(y * grid.width + 39)].squaredNorm(), 0.0f);
  EXPECT_EQ(grid.normals[static_cast<size_t>(y * grid.width + 40)].squaredNorm(), 0.0f);
  EXPECT_NEAR(grid.normals[static_cast<size_t>(y * grid.width + 38)].z(), -1.0f, 1e-5f);
  EXPECT_NEAR(grid.normals[static_cast<size_t>(y * grid.width + 41)].z(), -1.0f, 1e-5f);
}

TEST(DenseDepth, Sse2BlockDepthsEqualTheScalarLoop) {
  cv::Mat depth(480, 640, CV_16UC1);
  cv::RNG rng(7);
  rng.fill(depth, cv::RNG::UNIFORM, 1000, 1040);  // within the 5 % spread
  for (int k = 0; k < 15000; ++k) {              // holes, far and out-of-range readings
    const int x = rng.uniform(0, 640), y = rng.uniform(0, 480);
    const int kind = rng.uniform(0, 4);
    depth.at<uint16_t>(y, x) = kind == 0 ? 0 : kind == 1 ? 250 : kind == 2 ? 40000 : 1400;
  }
  for (double max_m : {6.0, 1.02}) {  // 1.02: about half of each block out of range
    DepthOptions o;
    o.max_m = max_m;
    std::vector<float> simd, scalar;
    block_depths(depth, o, 3, true, simd);
    block_depths(depth, o, 3, false, scalar);
    ASSERT_EQ(simd.size(), scalar.size());
    int valid = 0;
    for (size_t i = 0; i < simd.size(); ++i) {
      ASSERT_EQ(simd[i], scalar[i]) << "cell " << i;
      valid += simd[i] > 0.0f;
    }
    EXPECT_GT(valid, 100);
    EXPECT_LT(valid, static_cast<int>(simd.size()) - 100);
  }
}

TEST(DenseDepth, DistortionInvertsTheLensTable) {
  PinholeCamera cam = test::test_camera();
  cam.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // fr1's
  sensors::Lens lens;
  lens.reset(cam, true);
  for (double v = 20; v < cam.height - 20; v += 37) {
    for (double u = 20; u < cam.width - 20; u += 41) {
      const Eigen::Vector2d raw = cam.distort(u, v);
      const Eigen::Vector2f back = lens.ideal(float(raw.x()), float(raw.y()));
      EXPECT_NEAR(back.x(), u, 1e-2) << u << ", " << v;
      EXPECT_NEAR(back.y(), v, 1e-2) << u << ", " << v;
    }
  }
}

// Two views of the synthetic room (walls, floor, block: every direction constrained); the
// point-to-plane term alone, started 6 mm and 0.4 degrees off, from the room's corner, recovers the motion.
TEST(DenseRefinement, RecoversAKnownMotionFromDepthAlone) {
  const PinholeCamera cam = test::test_camera();
  // Looking down into a corner of the room, so that the back wall, a side wall and the floor
  // (three independent normals) fill the view.
  const test::SyntheticScene scene(3, 2.5);
  const Eigen::Isometry3d T_world_ref = se3::exp((Vector6d() << 0.3, -0.3, 0.0, -0.35, 0.45, 0.0).finished());
  const Eigen::Isometry3d T_ref_cur = se3::exp((Vector6d() << 0.03, 0.01, -0.02, 0.01, 0.02, -0.015).finished());
  const RgbdFrame ref_frame = scene.render(T_world_ref, cam, 0);
  const RgbdFrame cur_frame = scene.render(T_world_ref * T_ref_cur, cam, 33000);
  sensors::Lens lens;
  lens.reset(cam, false);
  DenseDepth ref, cur;
  build_dense_depth(ref_frame.depth_mm, lens, DepthOptions{}, 3, ref);
  build_dense_depth(cur_frame.depth_mm, lens, DepthOptions{}, 3, cur);

  DenseTerm term;
  term.ref = &ref;
  term.cur = &cur;
  term.options.stride = 1;
  term.sigma_z_coeff = 1.4e-3;
  RefinementOptions ro;
  ro.max_iterations = 20;
  const Eigen::Isometry3d start =
      se3::boxplus(T_ref_cur, (Vector6d() << 0.004, -0.003, 0.003, 0.004, -0.003, 0.004).finished());
  const RefinementResult r = refine_motion({}, {}, cam, start, ro, &term);  // one association, as the pipeline
  const Eigen::Isometry3d& T = r.T_ref_cur;
  ASSERT_GT(r.dense_residuals, 3000);
  int axis[3] = {0, 0, 0};  // the room's axis each normal lies along: all three in view
  for (const Eigen::Vector3f& n : ref.normals) {
    if (n.squaredNorm() == 0.0f) continue;
    int k = 0;
    (T_world_ref.linear() * n.cast<double>()).cwiseAbs().maxCoeff(&k);
    ++axis[k];
  }
  EXPECT_GT(std::min({axis[0], axis[1], axis[2]}), 300);
  // Millimetre depth rounding and 8-pixel cells: half a millimetre and a hundredth of a degree.
  EXPECT_LT((T.translation() - T_ref_cur.translation()).norm(), 5e-4);
  EXPECT_LT(so3::angle(T.linear().transpose() * T_ref_cur.linear()) * 180.0 / kPi, 0.015);
  EXPECT_GT((start.translation() - T_ref_cur.translation()).norm(), 5e-3);
}

}  // namespace
}  // namespace kestrel::vo
