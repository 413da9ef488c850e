// The renderer against geometry known in closed form: depth of a plane and of a box equals
// the analytic depth within the Kinect's disparity quantisation; every pixel back-projects
// onto the surface it shows; textured walls give FAST corners at several pyramid levels and
// the blank wall few; the texture span loops equal per-texel lookups in the unpadded levels;
// where the shading chunks fall does not change the image.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/sim/kinect_depth.h"
#include "drivers/sim/random.h"
#include "drivers/sim/renderer.h"
#include "drivers/sim/rgb_sensor.h"
#include "drivers/sim/texture.h"
#include "sim_fixture.h"

namespace kestrel::sim {
namespace {

using test::exact_camera;
using test::look;

// Half a disparity step at depth z, plus the millimetre rounding.
double quantisation_tolerance_m(const DepthOptions& o, double z) { return 0.5 * inverse_depth_step(o) * z * z + 6e-4; }

Eigen::Vector3d ray_world(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& c, int u, int v) {
  return T_world_camera.linear() * Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0);
}

TEST(RenderTest, DepthOfATiltedPlaneIsAnalytic) {
  const World& world = test::plane_world(false);
  const CameraOptions options = exact_camera();
  Renderer renderer(world, options, 1);
  // Turned 25 degrees and pitched 10 degrees, so the depth varies across the image.
  const Eigen::Isometry3d T = look({0.0, 0.2, 1.5}, 0.44, 0.17);
  const RgbdFrame frame = renderer.render(T, 0, 0);
  EXPECT_EQ(frame.sensor, "simulator");  // consumers take the simulator's profile by it
  const PinholeCamera& c = options.camera;
  int valid = 0, expected = 0;
  for (int v = 0; v < c.height; v += 3)
    for (int u = 0; u < c.width; u += 3) {
      const uint16_t mm = frame.depth_mm.at<uint16_t>(v, u);
      const Eigen::Vector3d d = ray_world(T, c, u, v);
      const double z = (3.0 - T.translation().x()) / d.x();  // the plane x = 3
      const Eigen::Vector3d hit = T.translation() + z * d;
      // On the wall's rectangle and well within range, a reading must be there.
      if (std::abs(hit.y()) < 3.9 && hit.z() > -0.9 && hit.z() < 3.9 && z < 3.5) ++expected;
      if (mm == 0) continue;
      ++valid;
      ASSERT_NEAR(mm * 1e-3, z, quantisation_tolerance_m(options.depth, z)) << "pixel " << u << ", " << v;
    }
  EXPECT_GT(expected, 10000);
  EXPECT_GT(valid, 0.95 * expected);
}

TEST(RenderTest, DepthOfABoxMatchesRayCasting) {
  const World& world = test::plane_world(true);
  const CameraOptions options = exact_camera();
  Renderer renderer(world, options, 1);
  const Eigen::Isometry3d T = look({0.2, 0.0, 1.6}, 0.05, 0.1);
  const RgbdFrame frame = renderer.render(T, 0, 0);
  const PinholeCamera& c = options.camera;
  int box_pixels = 0, checked = 0, disagree = 0;
  for (int v = 0; v < c.height; v += 2)
    for (int u = 0; u < c.width; u += 2) {
      const uint16_t mm = frame.depth_mm.at<uint16_t>(v, u);
      if (mm == 0) continue;
      const Eigen::Vector3d d = ray_world(T, c, u, v);
      const auto hit = world.raycast(T.translation(), d.normalized(), 20.0);
      ASSERT_TRUE(hit.has_value()) << "pixel " << u << ", " << v << " has depth but its ray hits nothing";
      const double z = hit->distance / d.norm();
      ++checked;
      if (world.surfaces()[hit->surface].box >= 0) ++box_pixels;
      if (std::abs(mm * 1e-3 - z) > quantisation_tolerance_m(options.depth, z)) ++disagree;
    }
  EXPECT_GT(box_pixels, 2000);  // the box is well in view (a 0.5 m cube at ~1.8 m)
  // Only pixels whose centre lies within float rounding of a silhouette may disagree.
  EXPECT_LT(disagree, 0.002 * checked) << disagree << " of " << checked;
}

TEST(RenderTest, PixelsBackProjectOntoTheSurfacesTheyShow) {
  const World& world = test::builtin("room");
  const CameraOptions options = exact_camera();
  Renderer renderer(world, options, 1);
  const PinholeCamera& c = options.camera;
  for (const Eigen::Isometry3d& T : {look({8.0, 3.5, 1.3}, 0.0, 0.2), look({3.0, 4.5, 1.0}, -2.0, 0.35),
                                     look({5.5, 2.0, 2.0}, 1.7, -0.3)}) {
    const RgbdFrame frame = renderer.render(T, 0, 0);
    const cv::Mat ideal = renderer.ideal_depth();
    const cv::Mat ids = renderer.surface_ids();
    int seen = 0;
    for (int v = 0; v < c.height; v += 4)
      for (int u = 0; u < c.width; u += 4) {
        const int id = ids.at<int>(v, u);
        if (id < 0) continue;
        ++seen;
        const Surface& s = world.surfaces()[id];
        const double z = static_cast<double>(ideal.at<float>(v, u));
        const Eigen::Vector3d p = T * c.backproject(u, v, z);
        ASSERT_LT(std::abs(s.plane_distance(p)), 1e-4 * z + 1e-5) << "pixel " << u << ", " << v;
        const double ss = s.axis_s.dot(p - s.origin), tt = s.axis_t.dot(p - s.origin);
        ASSERT_TRUE(ss > -1e-3 && ss < s.width + 1e-3 && tt > -1e-3 && tt < s.height + 1e-3)
            << "pixel " << u << ", " << v << " lies outside surface " << id;
        const uint16_t mm = frame.depth_mm.at<uint16_t>(v, u);
        if (mm == 0) continue;
        const Eigen::Vector3d q = T * c.backproject(u, v, mm * 1e-3);
        ASSERT_LT(std::abs(s.plane_distance(q)), 1.5 * quantisation_tolerance_m(options.depth, z));
      }
    EXPECT_EQ(seen, (c.width / 4) * (c.height / 4));  // a closed room: every pixel sees a surface
  }
}

// FAST corners (threshold 20, non-max suppression) at pyramid levels 0, 1, 2.
std::array<int, 3> fast_per_level(const cv::Mat& rgb) {
  cv::Mat grey;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  std::array<int, 3> counts{};
  for (int level = 0; level < 3; ++level) {
    std::vector<cv::KeyPoint> corners;
    cv::FAST(grey, corners, 20, true);
    counts[level] = static_cast<int>(corners.size());
    cv::Mat down;
    cv::pyrDown(grey, down);
    grey = down;
  }
  return counts;
}

TEST(RenderTest, TexturedWallsHaveCornersAtSeveralScalesAndTheBlankWallFew) {
  const World& world = test::builtin("room");
  Renderer renderer(world, CameraOptions{}, 3);
  // 2 m from the brick wall (south, cluttered) and from the blank wall (north), level.
  const auto textured = fast_per_level(renderer.render(look({8.0, 2.0, 1.5}, -1.5708), 0, 0).rgb);
  const auto blank = fast_per_level(renderer.render(look({7.5, 5.0, 1.8}, 1.5708, -0.1), 0, 1).rgb);
  const int minimum[3] = {300, 100, 25};
  for (int level = 0; level < 3; ++level) {
    SCOPED_TRACE("pyramid level " + std::to_string(level));
    EXPECT_GT(textured[level], minimum[level]);
    EXPECT_LT(blank[level] * 5, textured[level]);
  }
}

// The auto-exposure's factor, by hand: it meters the grey clipped at 255, and acts only above
// the bound.
TEST(RgbSensor, AutoExposureLowersOnlyAFrameBrighterThanTheBoundAndMetersTheClippedGrey) {
  const int w = 64, h = 48;
  const auto planes_of = [&](float left, float right) {
    std::vector<float> p(static_cast<size_t>(w * h));
    for (int v = 0; v < h; ++v)
      for (int u = 0; u < w; ++u) p[static_cast<size_t>(v * w + u)] = u < w / 2 ? left : right;
    return std::array<std::vector<float>, 3>{p, p, p};
  };
  const auto gain = [&](float left, float right, double bound) {
    auto a = planes_of(left, right);
    std::vector<float> planes[3] = {a[0], a[1], a[2]};
    return auto_exposure_gain(planes, w, h, bound);
  };
  EXPECT_EQ(gain(100, 100, 160), 1.0f);
  EXPECT_NEAR(gain(400, 400, 160), 0.4f, 1e-4);
  // Unclipped the mean would be 525; clipped, (255 + 50) / 2 = 152.5: within the bound.
  EXPECT_EQ(gain(1000, 50, 160), 1.0f);
  // (255 + 200 g) / 2 = 160 with 1000 g >= 255: g = 0.325.
  EXPECT_NEAR(gain(1000, 200, 160), 0.325f, 1e-4);
  EXPECT_EQ(gain(1000, 1000, 0), 1.0f) << "0: off";
}

// Under the floor's lamps a fixed exposure washes the frame out; with the auto-exposure its mean
// grey stays within a Kinect's and the clipped highlights shrink; the room, dimmer, is rendered
// exactly as with a fixed exposure.
TEST(RenderTest, AFrameUnderTheLampsIsNotWashedOutAndADimOneIsUntouched) {
  const auto stats = [](const cv::Mat& rgb) {
    cv::Mat grey;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    return std::make_pair(cv::mean(grey)[0], cv::countNonZero(grey >= 250) / static_cast<double>(grey.total()));
  };
  CameraOptions fixed;
  fixed.rgb.max_mean_grey = 0.0;
  const World& floor = test::builtin("floor");
  const Eigen::Isometry3d under_lamps = look({6.5, 2.5, 1.2}, 1.5708);
  const auto [fixed_mean, fixed_clipped] = stats(Renderer(floor, fixed, 3).render(under_lamps, 0, 0).rgb);
  const auto [auto_mean, auto_clipped] = stats(Renderer(floor, CameraOptions{}, 3).render(under_lamps, 0, 0).rgb);
  EXPECT_GT(fixed_mean, 180.0) << "the case this is about";
  EXPECT_LT(auto_mean, 161.0);
  EXPECT_GT(auto_mean, 130.0);
  EXPECT_LT(auto_clipped, 0.5 * fixed_clipped);
  const World& room = test::builtin("room");
  const Eigen::Isometry3d dim = look({8.0, 2.0, 1.5}, -1.5708);
  const cv::Mat a = Renderer(room, fixed, 3).render(dim, 0, 0).rgb, b = Renderer(room, CameraOptions{}, 3).render(dim, 0, 0).rgb;
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

// The spans (SIMD groups of 4 and 8 pixels plus scalar tails, stored wrap copies) against
// bilinear lookups written out on the unpadded level with explicit wrapping.
TEST(RenderTest, TextureSpansEqualPerTexelBilinearLookups) {
  Rng rng(7);
  cv::Mat image(64, 64, CV_32FC3);
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 64; ++c)
      image.at<cv::Vec3f>(r, c) = cv::Vec3f(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()),
                                            static_cast<float>(rng.uniform()));
  MipTexture tex(image);
  tex.add_grey_levels();
  for (int l = 0; l < tex.levels(); ++l) {
    const std::vector<uint32_t> level = tex.level(l);
    const uint32_t side = static_cast<uint32_t>(tex.size() >> l), mask = side - 1;
    ASSERT_EQ(level.size(), static_cast<size_t>(side) * side);
    for (int trial = 0; trial < 40; ++trial) {
      const int n = 1 + trial;  // every remainder of the groups of 4 and 8
      uint32_t x = static_cast<uint32_t>(rng.next()), y = static_cast<uint32_t>(rng.next());
      const int32_t dx = static_cast<int32_t>(rng.below(1 << 18)) - (1 << 17);
      const int32_t dy = static_cast<int32_t>(rng.below(1 << 18)) - (1 << 17);
      std::vector<uint32_t> span(static_cast<size_t>(n)), grey(static_cast<size_t>(n));
      tex.bilinear_span(l, x, y, dx, dy, n, span.data());
      tex.grey_span(l, x, y, dx, dy, n, grey.data());
      for (int i = 0; i < n; ++i) {
        const uint32_t ix = (x >> 16) & mask, iy = (y >> 16) & mask, wx = (x >> 8) & 255u, wy = (y >> 8) & 255u;
        const uint32_t ix1 = (ix + 1) & mask, iy1 = (iy + 1) & mask;
        uint32_t expected = 0;
        for (int ch = 0; ch < 3; ++ch) {
          auto t = [&](uint32_t r, uint32_t c) { return (level[r * side + c] >> (8 * ch)) & 255u; };
          const uint32_t top = (t(iy, ix) * (256u - wx) + t(iy, ix1) * wx) >> 8;
          const uint32_t bottom = (t(iy1, ix) * (256u - wx) + t(iy1, ix1) * wx) >> 8;
          expected |= ((top * (256u - wy) + bottom * wy) >> 8) << (8 * ch);
        }
        ASSERT_EQ(span[static_cast<size_t>(i)], expected) << "level " << l << " n " << n << " pixel " << i;
        ASSERT_EQ(grey[static_cast<size_t>(i)], expected & 255u) << "level " << l << " n " << n << " pixel " << i;
        x += static_cast<uint32_t>(dx);
        y += static_cast<uint32_t>(dy);
      }
    }
  }
}


// Where the renderer's 16-pixel shading chunks fall must not change what a pixel shows: the
// same rays, moved 5 px along the rows by the principal point, give the same image. A row's
// chunks start where each surface's run starts, so the shift moves them on the surfaces the
// image's left edge cuts (here the ceiling and the walls up to the lamps). Linear light over a
// chunk broke this near the lamps and shadow edges, at places that moved with the camera, and
// the VO read it as motion (docs/decisions/2026-12-06-stata-flights-rotation-drift.md).
TEST(RenderTest, WhatAPixelShowsDoesNotDependOnWhereTheShadingChunksFall) {
  const World& world = test::builtin("room");
  CameraOptions options = exact_camera();
  options.rgb.vignetting = 0.0;  // the only sensor effect that sees the principal point
  options.rgb.optics_blur = false;
  CameraOptions shifted = options;
  constexpr int kShift = 5;
  shifted.camera.cx += kShift;
  Renderer a(world, options, 1), b(world, shifted, 1);
  for (const Eigen::Isometry3d& T : {look({8.0, 3.5, 1.3}, 0.0, -1.2), look({3.0, 4.5, 1.0}, -2.0, 0.35),
                                     look({5.5, 2.0, 2.0}, 1.7, -0.9)}) {
    const cv::Mat ia = a.render(T, 0, 0).rgb, ib = b.render(T, 0, 0).rgb;
    std::vector<int> diffs;
    for (int v = 0; v < ia.rows; ++v)
      for (int u = 0; u + kShift < ia.cols; ++u)
        for (int ch = 0; ch < 3; ++ch)
          diffs.push_back(std::abs(ia.at<cv::Vec3b>(v, u)[ch] - ib.at<cv::Vec3b>(v, u + kShift)[ch]));
    std::sort(diffs.begin(), diffs.end());
    double mean = 0;
    for (int d : diffs) mean += d;
    mean /= static_cast<double>(diffs.size());
    // What remains is the texture's mip level, chosen per chunk. Linear light gave 0.12 and 4
    // grey levels on the two views up at the lamps; the light map sampled as it is, 0.03 and 1
    // (bounds with room for another compiler's rounding).
    EXPECT_LT(mean, 0.06) << "mean difference, grey levels";
    EXPECT_LE(diffs[diffs.size() - diffs.size() / 1000], 2) << "99.9th percentile difference, grey levels";
  }
}

}  // namespace
}  // namespace kestrel::sim
