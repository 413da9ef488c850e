// The integrator's answer equals OctoMap's computeUpdate (the core of insertPointCloud), cell
// for cell, with both methods, on scenes built to be hard: random clutter, rays along cell
// boundaries, camera centres on cell corners, rays cut at max range.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

#include "common/error.h"
#include "mapper/scan.h"
#include "mapper/scan_integrator.h"
#include "test/mapper/octomap_reference.h"
#include "test/mapper/scene.h"

namespace kestrel::mapper {
namespace {

using Method = ScanIntegrator::Method;
using test::Scene;

Scene random_scene(std::mt19937& rng) {
  Scene scene(Eigen::Vector3d(-3.0, -3.0, 0.0), Eigen::Vector3d(3.0, 3.0, 2.7));
  std::uniform_real_distribution<double> pos(-2.8, 2.8), height(0.0, 2.5), size(0.05, 0.8);
  for (int i = 0; i < 12; ++i) {
    const Eigen::Vector3d c(pos(rng), pos(rng), height(rng));
    const Eigen::Vector3d h(size(rng), size(rng), size(rng));
    scene.add_box(c - 0.5 * h, c + 0.5 * h);
  }
  return scene;
}

void expect_same_as_octomap(const Scan& scan, double resolution, const ScanOptions& options,
                            const std::string& label) {
  const test::OctomapUpdate reference = test::octomap_update(scan, resolution, options.max_range_m);
  ScanIntegrator integrator(resolution, options);
  for (const Method method : {Method::kCellSearch, Method::kRayTrace}) {
    ScanUpdate update;
    integrator.compute(scan, update, method);
    EXPECT_EQ(test::count_differences(update, reference), 0u)
        << label << (method == Method::kCellSearch ? " (cell search)" : " (ray trace)")
        << ": octomap free " << reference.free.size() << " occupied " << reference.occupied.size()
        << ", mine free " << update.free.size() << " occupied " << update.occupied.size();
  }
}

void expect_same_as_octomap_discretized(const Scan& scan, double resolution, const ScanOptions& options,
                                        const std::string& label) {
  const test::OctomapUpdate reference = test::octomap_discrete_update(scan, resolution, options.max_range_m);
  ScanIntegrator integrator(resolution, options);
  ScanUpdate update;
  integrator.compute(scan, update, Method::kDiscretized);
  EXPECT_EQ(test::count_differences(update, reference), 0u)
      << label << " (discretized): octomap free " << reference.free.size() << " occupied "
      << reference.occupied.size() << ", mine free " << update.free.size() << " occupied "
      << update.occupied.size();
  EXPECT_GT(reference.free.size() + reference.occupied.size(), 0u) << label;
}

TEST(ScanIntegrator, SameCellsAsOctomapInRandomClutter) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pos(-2.0, 2.0), z(0.3, 2.2);
  for (int trial = 0; trial < 12; ++trial) {
    const Scene scene = random_scene(rng);
    const Eigen::Vector3d eye(pos(rng), pos(rng), z(rng));
    const Eigen::Vector3d target(pos(rng), pos(rng), z(rng));
    if ((target - eye).norm() < 0.3) continue;
    const RgbdFrame frame = scene.render(test::kinect_camera(160, 120), test::look_at(eye, target), trial);
    ScanOptions options;
    options.stride = 1 + trial % 3;
    options.max_range_m = trial % 2 ? 4.0 : 2.0;  // 2 m cuts many rays
    const double resolution = trial % 4 == 3 ? 0.05 : 0.1;
    const Scan scan = make_scan(decimate(frame, options.stride), test::look_at(eye, target), options, "test");
    expect_same_as_octomap(scan, resolution, options, "trial " + std::to_string(trial));
    expect_same_as_octomap_discretized(scan, resolution, options, "trial " + std::to_string(trial));
  }
}

TEST(ScanIntegrator, SameCellsAsOctomapWhenRaysRunAlongCellBoundaries) {
  // Camera centres exactly on cell corners and edges, looking along the axes and diagonals,
  // walls and boxes on cell boundaries: rays graze edges and end on faces, so OctoMap's own
  // rounding decides many cells and the cell search has to fall back to walking rays.
  Scene scene(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(2.0, 2.0, 2.0));
  scene.add_box(Eigen::Vector3d(0.5, -0.3, 0.0), Eigen::Vector3d(0.8, 0.3, 1.2));
  scene.add_box(Eigen::Vector3d(-1.0, 0.6, 0.4), Eigen::Vector3d(-0.6, 1.0, 0.8));
  const Eigen::Vector3d eyes[] = {{0.0, 0.0, 1.0}, {0.1, -0.2, 0.5}, {-0.3, 0.0, 1.3}};
  const Eigen::Vector3d targets[] = {{2.0, 0.0, 1.0}, {0.0, 2.0, 1.0}, {1.0, 1.0, 0.0},
                                     {-2.0, -2.0, 1.0}, {0.0, 0.0, 0.0}};
  int case_no = 0;
  for (const auto& eye : eyes) {
    for (const auto& target : targets) {
      const Eigen::Isometry3d T = test::look_at(eye, target);
      const RgbdFrame frame = scene.render(test::kinect_camera(64, 48), T, case_no);
      ScanOptions options;
      options.stride = 1;
      const Scan scan = make_scan(frame, T, options, "test");
      expect_same_as_octomap(scan, 0.1, options, "case " + std::to_string(case_no));
      expect_same_as_octomap_discretized(scan, 0.1, options, "case " + std::to_string(case_no++));
    }
  }
}

TEST(ScanIntegrator, DiscretizedIsOctomapsDiscreteUpdateAndCastsOneRayPerEndpointCell) {
  // The discretised mode: the cells of OctoMap's computeDiscreteUpdate, with one walked ray per
  // distinct endpoint cell, chosen by ScanOptions::discretize; a different map from the exact
  // one.
  std::mt19937 rng(5);
  const Scene scene = random_scene(rng);
  const Eigen::Isometry3d T = test::look_at({0.13, 0.27, 1.21}, {2.0, 1.0, 0.8});
  for (const double max_range : {4.0, 1.5}) {  // 1.5 m: most endpoint centres are cut
    ScanOptions options;
    options.max_range_m = max_range;
    options.discretize = true;
    const Scan scan = make_scan(decimate(scene.render(test::kinect_camera(), T, 0), options.stride), T,
                                options, "test");
    ScanIntegrator integrator(0.1, options);
    ScanUpdate update;
    integrator.compute(scan, update);  // the options' method
    const test::OctomapUpdate discrete = test::octomap_discrete_update(scan, 0.1, max_range);
    EXPECT_EQ(test::count_differences(update, discrete), 0u) << max_range;
    // One ray per distinct key of the scan's points.
    octomap::OcTree tree(0.1);
    octomap::KeySet endpoint_keys;
    for (const auto& p : scan.valid_points()) endpoint_keys.insert(tree.coordToKey(p));
    EXPECT_EQ(update.rays_traced, endpoint_keys.size());
    EXPECT_LT(update.rays_traced, update.rays / 5);
    EXPECT_LE(update.occupied.size(), endpoint_keys.size());  // centres beyond max range: none
    if (max_range == 4.0) {
      EXPECT_GT(update.occupied.size(), endpoint_keys.size() / 2);
    }
    // Not the exact map (other rays: to the cells' centres, one per cell).
    const test::OctomapUpdate exact = test::octomap_update(scan, 0.1, max_range);
    EXPECT_GT(test::count_differences(update, exact), 0u);
  }
}

TEST(ScanIntegrator, DiscretizedWithReadingsFarBeyondMaxRange) {
  // Readings up to 60 m (beyond the integrator's grid) with a 2 m max range: their endpoint
  // cells are deduplicated outside the grid, and their centres' rays cut at max range.
  Scene scene(Eigen::Vector3d(-40.0, -40.0, -30.0), Eigen::Vector3d(60.0, 40.0, 30.0));
  scene.add_box(Eigen::Vector3d(1.0, -0.5, -0.5), Eigen::Vector3d(1.6, 0.4, 0.4));
  const Eigen::Isometry3d T = test::look_at({0.03, 0.02, 0.01}, {10.0, 0.7, 0.2});
  ScanOptions options;
  options.stride = 2;
  options.max_range_m = 2.0;
  const Scan scan = make_scan(decimate(scene.render(test::kinect_camera(), T, 0), options.stride), T,
                              options, "test");
  expect_same_as_octomap_discretized(scan, 0.1, options, "far readings");
}

TEST(ScanIntegrator, CellSearchTracesOnlyAFewRays) {
  std::mt19937 rng(3);
  const Scene scene = random_scene(rng);
  // (A camera centre exactly on a cell corner makes every ray ambiguous at its start, so all
  // are walked: still exact, only slower; see SameCellsAsOctomapWhenRaysRunAlongCellBoundaries.)
  const Eigen::Isometry3d T = test::look_at({0.13, 0.27, 1.21}, {2.0, 1.0, 0.8});
  ScanOptions options;
  const Scan scan = make_scan(decimate(scene.render(test::kinect_camera(), T, 0), options.stride), T,
                              options, "test");
  ScanIntegrator integrator(0.1, options);
  ScanUpdate update;
  integrator.compute(scan, update, Method::kCellSearch);
  ASSERT_GT(update.rays, 10000u);
  EXPECT_LT(update.rays_traced, update.rays / 5) << "the cell search should not walk most rays";
  EXPECT_GT(update.free.size(), 100u);
}

// freiburg1's calibrated lens (drivers/tum/tum_camera.cpp): 5-8 px over most of the image.
constexpr std::array<double, 5> kFr1Distortion{0.2624, -0.9531, -0.0054, 0.0026, 1.1633};

TEST(Scan, DecimatedScanEqualsMakeScanOfTheDecimatedFrame) {
  std::mt19937 rng(11);
  const Scene scene = random_scene(rng);
  const Eigen::Isometry3d T = test::look_at({-1.0, 0.2, 1.1}, {1.5, -0.3, 0.8});
  RgbdFrame frame = scene.render(test::kinect_camera(), T, 5);
  frame.depth_mm.at<uint16_t>(237, 322) = 0;   // a hole and a too-near reading on the stride-5 grid
  frame.depth_mm.at<uint16_t>(242, 327) = 50;
  for (const bool distorted : {false, true}) {
    // The rendered image is the same either way: with distortion the frame claims a lens, so
    // both paths read it through the same lens grid.
    frame.camera.distortion = distorted ? kFr1Distortion : std::array<double, 5>{};
    for (const int stride : {1, 2, 3, 5, 7}) {
      ScanOptions options;
      options.stride = stride;
      options.min_range_m = 0.1;
      const Scan expected = make_scan(decimate(frame, stride), T, options, "test");
      Scan scan;
      make_decimated_scan(frame, T, options, "test", scan);
      ASSERT_EQ(scan.cols, expected.cols) << "stride " << stride;
      ASSERT_EQ(scan.rows, expected.rows);
      EXPECT_EQ(scan.camera.fx, expected.camera.fx);
      EXPECT_EQ(scan.camera.cx, expected.camera.cx);
      EXPECT_EQ(scan.camera.cy, expected.camera.cy);
      EXPECT_FALSE(scan.camera.distorted());
      EXPECT_EQ(scan.num_points, expected.num_points);
      EXPECT_GT(scan.num_points, 0u);
      EXPECT_EQ(scan.valid, expected.valid);
      for (size_t i = 0; i < scan.points.size(); ++i) {
        if (!expected.valid[i]) continue;
        ASSERT_EQ(scan.points[i], expected.points[i]) << "stride " << stride << " pixel " << i;
      }
    }
  }
  frame.camera.distortion = {};
  EXPECT_EQ(decimate(frame, 5).depth_mm.at<uint16_t>(47, 64), 0);  // the hole is on the grid
}

// A distorted source: each node of the (ideal) grid reads the raw pixel where the lens images
// its ray, so a single reading lands on the node whose ray it was taken along.
TEST(Scan, DistortedDepthIsReadWhereTheLensImagesEachNode) {
  RgbdFrame frame;
  frame.camera = test::kinect_camera();
  frame.camera.distortion = kFr1Distortion;
  frame.utime = 1;
  frame.depth_mm = cv::Mat(frame.camera.height, frame.camera.width, CV_16UC1, cv::Scalar(0));
  ScanOptions options;
  options.stride = 5;  // grid 128 x 96, node (c, r) at full-size ideal pixel (2 + 5c, 2 + 5r)
  const int c = 10, r = 8;
  const Eigen::Vector2d raw = frame.camera.distort(2 + 5 * c, 2 + 5 * r);
  ASSERT_GT((raw - Eigen::Vector2d(2 + 5 * c, 2 + 5 * r)).norm(), 5.0) << "the lens must matter here";
  frame.depth_mm.at<uint16_t>(int(std::lround(raw.y())), int(std::lround(raw.x()))) = 2000;
  const Eigen::Isometry3d T = test::look_at({0.3, -0.2, 1.0}, {2.0, 0.5, 1.2});
  Scan scan;
  make_decimated_scan(frame, T, options, "test", scan);
  ASSERT_EQ(scan.num_points, 1u);
  const size_t node = static_cast<size_t>(r * scan.cols + c);
  ASSERT_TRUE(scan.valid[node]);
  const Eigen::Vector3d expected = T * scan.camera.backproject(c, r, 2.0);
  EXPECT_NEAR(scan.points[node].x(), expected.x(), 1e-5);
  EXPECT_NEAR(scan.points[node].y(), expected.y(), 1e-5);
  EXPECT_NEAR(scan.points[node].z(), expected.z(), 1e-5);
  // Read as ideal (no lens), the same reading is a different ray, centimetres away at 2 m.
  frame.camera.distortion = {};
  make_decimated_scan(frame, T, options, "test", scan);
  EXPECT_EQ(scan.num_points, 0u) << "the raw pixel is not on the plain stride-5 grid";

  // Readings everywhere: the corners' rays leave the raw image (this lens pulls them outwards),
  // so those nodes have none; the centre has one, at full resolution too.
  frame.camera.distortion = kFr1Distortion;
  frame.depth_mm.setTo(1500);
  for (const int stride : {5, 1}) {
    options.stride = stride;
    make_decimated_scan(frame, T, options, "test", scan);
    EXPECT_FALSE(scan.valid[0]) << "stride " << stride;
    EXPECT_TRUE(scan.valid[static_cast<size_t>(scan.rows / 2 * scan.cols + scan.cols / 2)]);
    EXPECT_LT(scan.num_points, static_cast<size_t>(scan.cols * scan.rows));
    EXPECT_GT(scan.num_points, static_cast<size_t>(scan.cols * scan.rows) * 9 / 10);
  }
  const RgbdFrame full = decimate(frame, 1);  // resampled, not a copy, when the lens distorts
  EXPECT_FALSE(full.camera.distorted());
  EXPECT_EQ(full.depth_mm.at<uint16_t>(0, 0), 0);
}

TEST(Scan, MinRangeKeepsReadingsAtOrBeyondIt) {
  // A reading is a ray iff it is not 0 and not nearer than min_range (a reading exactly at
  // min_range is kept), for whole and fractional millimetre limits.
  RgbdFrame frame;
  frame.camera = test::kinect_camera(8, 1);
  frame.depth_mm = cv::Mat(1, 8, CV_16UC1);
  const uint16_t mm[8] = {0, 1, 2, 499, 500, 501, 65534, 65535};
  for (int u = 0; u < 8; ++u) frame.depth_mm.at<uint16_t>(0, u) = mm[u];
  for (const double min_range : {0.0, 0.0005, 0.001, 0.0015, 0.4995, 0.5, 0.5001, 65.535, 70.0}) {
    ScanOptions options;
    options.stride = 1;
    options.max_range_m = 100.0;
    options.min_range_m = min_range;
    const Scan scan = make_scan(frame, Eigen::Isometry3d::Identity(), options, "test");
    for (int u = 0; u < 8; ++u) {
      const bool expected = mm[u] != 0 && !(mm[u] < min_range * 1000.0);
      EXPECT_EQ(scan.valid[static_cast<size_t>(u)] != 0, expected) << min_range << " " << mm[u];
    }
  }
}

TEST(ScanIntegrator, ZeroDepthMarksNothing) {
  RgbdFrame frame;
  frame.camera = test::kinect_camera(32, 24);
  frame.depth_mm = cv::Mat(24, 32, CV_16UC1, cv::Scalar(0));
  ScanOptions options;
  options.stride = 1;
  const Scan scan = make_scan(frame, Eigen::Isometry3d::Identity(), options, "test");
  EXPECT_EQ(scan.num_points, 0u);
  ScanIntegrator integrator(0.1, options);
  ScanUpdate update;
  for (const Method method : {Method::kCellSearch, Method::kRayTrace, Method::kDiscretized}) {
    integrator.compute(scan, update, method);
    EXPECT_TRUE(update.free.empty());
    EXPECT_TRUE(update.occupied.empty());
  }
}

TEST(ScanIntegrator, FarCameraIsAnInputError) {
  RgbdFrame frame;
  frame.camera = test::kinect_camera(8, 6);
  frame.depth_mm = cv::Mat(6, 8, CV_16UC1, cv::Scalar(1000));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = 1e6;  // far outside the 16-bit key range at 10 cm
  ScanOptions options;
  options.stride = 1;
  const Scan scan = make_scan(frame, T, options, "test");
  ScanIntegrator integrator(0.1, options);
  ScanUpdate update;
  EXPECT_THROW(integrator.compute(scan, update), InputError);
}

}  // namespace
}  // namespace kestrel::mapper
