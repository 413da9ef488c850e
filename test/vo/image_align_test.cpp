// Image alignment stages with known answers: the rotation prior on a synthetically rotated
// view, and the subpixel refinement of a match on an image shifted by a known fraction of a
// pixel (the scene rendered with a shifted principal point, so no resampling is involved).

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "common/geometry/so3.h"
#include "common/numbers.h"
#include "test/vo/synthetic_scene.h"
#include "vo/fast.h"
#include "vo/image_pyramid.h"
#include "vo/rotation_prior.h"
#include "vo/subpixel.h"

namespace kestrel::vo {
namespace {

ImagePyramid pyramid_of(const cv::Mat& image, int levels) {
  ImagePyramid p;
  p.build(image, levels, 0.85);
  return p;
}

// A smooth (band-limited) image: Gaussian blobs of 3..6 px, evaluated exactly at each pixel
// of a camera rotated by R_cur_prev and whose image is shifted by `shift`, so that no test
// result depends on resampling or aliasing.
cv::Mat blob_image(const PinholeCamera& cam, const Eigen::Matrix3d& R_cur_prev, const Eigen::Vector2d& shift) {
  struct Blob { double u, v, sigma, amplitude; };
  static const std::vector<Blob> blobs = [] {
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> u(-80, 720), v(-80, 560), s(3.0, 6.0), a(-90, 90);
    std::vector<Blob> out;
    for (int i = 0; i < 1500; ++i) out.push_back({u(rng), v(rng), s(rng), a(rng)});
    return out;
  }();
  cv::Mat image(cam.height, cam.width, CV_8UC1);
  const Eigen::Matrix3d R_prev_cur = R_cur_prev.transpose();
  for (int y = 0; y < cam.height; ++y) {
    for (int x = 0; x < cam.width; ++x) {
      // The prev pixel seen at this cur pixel.
      const Eigen::Vector3d ray(((x - shift.x()) - cam.cx) / cam.fx, ((y - shift.y()) - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d q = R_prev_cur * ray;
      const double u = cam.fx * q.x() / q.z() + cam.cx, v = cam.fy * q.y() / q.z() + cam.cy;
      double value = 128.0;
      for (const Blob& b : blobs) {
        const double d2 = (u - b.u) * (u - b.u) + (v - b.v) * (v - b.v);
        if (d2 < 12.0 * b.sigma * b.sigma) value += b.amplitude * std::exp(-0.5 * d2 / (b.sigma * b.sigma));
      }
      image.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(value);
    }
  }
  return image;
}


TEST(RotationPrior, RecoversARotationOfTheCameraFromCoarseImages) {
  const PinholeCamera cam = test::test_camera();
  const Eigen::Matrix3d R_cur_prev = so3::exp(Eigen::Vector3d(0.03, -0.05, 0.02));  // 3.4 degrees
  const ImagePyramid prev = pyramid_of(blob_image(cam, Eigen::Matrix3d::Identity(), {0, 0}), 4);
  const ImagePyramid cur = pyramid_of(blob_image(cam, R_cur_prev, {0, 0}), 4);
  RotationPrior prior;
  const int level = 3;  // 80 x 60, the pipeline's default
  const RotationPriorResult r = prior.estimate(prev.level(level), cur.level(level),
                                               cam.scaled(1.0 / double(1 << level)), Eigen::Matrix3d::Identity(), 30);
  const double error_deg = so3::angle(r.R_cur_prev.transpose() * R_cur_prev) * 180.0 / kPi;
  EXPECT_LT(error_deg, 0.3) << "after " << r.iterations << " iterations";
  EXPECT_GT(r.iterations, 1);
}

TEST(Subpixel, FindsAKnownShiftToFiveHundredthsOfAPixel) {
  const PinholeCamera cam = test::test_camera();
  const Eigen::Vector2f shift(0.37f, -0.21f);
  const ImagePyramid ref = pyramid_of(blob_image(cam, Eigen::Matrix3d::Identity(), {0, 0}), 1);
  const ImagePyramid cur = pyramid_of(blob_image(cam, Eigen::Matrix3d::Identity(), shift.cast<double>()), 1);
  // At the FAST corners of the reference, where the pipeline refines matches.
  std::vector<FastCorner> corners;
  FastScratch scratch;
  detect_fast9(ref.level(0), 10, true, corners, scratch);
  int tested = 0, within = 0;
  for (const FastCorner& c : corners) {
    if (c.x < 12 || c.y < 12 || c.x >= 640 - 12 || c.y >= 480 - 12) continue;
    const SubpixelResult r = refine_subpixel(ref.level(0), Eigen::Vector2i(c.x, c.y), cur.level(0),
                                             Eigen::Vector2f(float(c.x), float(c.y)), 9, 1.5f);
    ASSERT_TRUE(r.ok) << c.x << "," << c.y;
    const float error = (r.position - Eigen::Vector2f(float(c.x), float(c.y)) - shift).norm();
    within += error < 0.05f;
    EXPECT_LT(error, 0.2f) << c.x << "," << c.y;
    ++tested;
  }
  // 8-bit grey levels limit weak corners; the strong majority is within 0.05 px.
  EXPECT_GT(tested, 100);
  EXPECT_GE(within, tested * 9 / 10) << within << " of " << tested << " within 0.05 px";
}

TEST(Subpixel, SimdSumsEqualTheScalarOnesBitForBit) {
  // refine_subpixel's SSE2 path (rows converted once, sums four pixels at a time) must give
  // exactly the scalar reference's answer, for every window size and on textures from smooth
  // to raw noise, including starts that converge, wander off or leave the image.
  const PinholeCamera cam = test::test_camera();
  const cv::Mat smooth_ref = blob_image(cam, Eigen::Matrix3d::Identity(), {0, 0});
  const cv::Mat smooth_cur = blob_image(cam, Eigen::Matrix3d::Identity(), {0.37, -0.21});
  cv::Mat noise_ref(120, 161, CV_8UC1), noise_cur;
  cv::RNG(5).fill(noise_ref, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise_ref, noise_cur, cv::Size(3, 3), 0.6);
  const std::vector<std::pair<cv::Mat, cv::Mat>> pairs{{smooth_ref, smooth_cur}, {noise_ref, noise_cur}};
  std::mt19937 rng(9);
  int compared = 0, converged = 0;
  for (const auto& [ref, cur] : pairs) {
    std::uniform_int_distribution<int> px(0, ref.cols - 1), py(0, ref.rows - 1);
    std::uniform_real_distribution<float> jitter(-1.2f, 1.2f);
    for (int window = 3; window <= 15; window += 2) {
      for (int k = 0; k < 150; ++k) {
        const Eigen::Vector2i at(px(rng), py(rng));
        const Eigen::Vector2f start(float(at.x()) + jitter(rng), float(at.y()) + jitter(rng));
        const SubpixelResult a = refine_subpixel(ref, at, cur, start, window, 1.5f);
        const SubpixelResult b = refine_subpixel_scalar(ref, at, cur, start, window, 1.5f);
        ASSERT_EQ(a.ok, b.ok) << window << " " << at.transpose();
        ASSERT_EQ(a.iterations, b.iterations) << window << " " << at.transpose();
        ASSERT_EQ(a.position.x(), b.position.x()) << window << " " << at.transpose();
        ASSERT_EQ(a.position.y(), b.position.y()) << window << " " << at.transpose();
        ASSERT_EQ(a.rms_error, b.rms_error) << window << " " << at.transpose();
        ++compared;
        converged += a.ok;
      }
    }
  }
  EXPECT_GT(converged, compared / 4) << "too few refinements succeeded to compare";
  EXPECT_LT(converged, compared) << "some should fail (image border, shift limit)";
}

TEST(Subpixel, FailsWithoutMovingWhenThePatchLeavesTheImage) {
  const cv::Mat image(40, 40, CV_8UC1, cv::Scalar(100));
  const SubpixelResult r = refine_subpixel(image, Eigen::Vector2i(2, 2), image, Eigen::Vector2f(2, 2), 9, 1.5f);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.position, Eigen::Vector2f(2, 2));
}

}  // namespace
}  // namespace kestrel::vo
