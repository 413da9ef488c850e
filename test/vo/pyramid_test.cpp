// The pyramid's own integer filters against OpenCV's (the reference they replace): the grey
// conversion, the sigma-0.85 blur and each halving agree to within a grey level or two on a
// textured image, sizes and borders included.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "vo/image_pyramid.h"

namespace kestrel::vo {
namespace {

cv::Mat textured_rgb(int w, int h) {
  cv::Mat rgb(h, w, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(rgb, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(rgb, rgb, cv::Size(3, 3), 0.7);  // some structure, still strong gradients
  return rgb;
}

double max_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  double m = 0.0;
  cv::minMaxLoc(cv::abs(a - b) + cv::abs(b - a), nullptr, &m);
  return m;
}

TEST(Pyramid, MatchesOpenCvGreyBlurAndHalvings) {
  const cv::Mat rgb = textured_rgb(641, 479);  // odd sizes exercise the borders and ceil()
  ImagePyramid pyramid;
  pyramid.build(rgb, 4, 0.85);
  cv::Mat grey, expected;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  cv::GaussianBlur(grey, expected, cv::Size(5, 5), 0.85, 0.85, cv::BORDER_REFLECT_101);
  ASSERT_EQ(pyramid.level(0).size(), expected.size());
  EXPECT_LE(max_abs_diff(pyramid.level(0), expected), 2.0);
  for (int l = 1; l < 4; ++l) {
    cv::Mat down;
    cv::pyrDown(pyramid.level(l - 1), down);
    ASSERT_EQ(pyramid.level(l).size(), down.size()) << "level " << l;
    EXPECT_LE(max_abs_diff(pyramid.level(l), down), 1.0) << "level " << l;
  }
}

TEST(Pyramid, KernelSumsTo64AndIsSymmetric) {
  std::vector<int> k;
  gaussian_kernel_64(0.85, k);
  ASSERT_EQ(k.size(), 5u);
  EXPECT_EQ(k[0] + k[1] + k[2] + k[3] + k[4], 64);
  EXPECT_EQ(k[0], k[4]);
  EXPECT_EQ(k[1], k[3]);
  EXPECT_EQ(k[2], 30);  // 64 * 0.470 of the normalised sigma-0.85 Gaussian
}

TEST(Pyramid, WideKernelFallsBackToOpenCv) {
  const cv::Mat rgb = textured_rgb(64, 48);
  ImagePyramid pyramid;
  pyramid.build(rgb, 1, 2.5);
  cv::Mat grey, expected;
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  cv::GaussianBlur(grey, expected, cv::Size(11, 11), 2.5, 2.5, cv::BORDER_REFLECT_101);
  EXPECT_LE(max_abs_diff(pyramid.level(0), expected), 2.0);  // the grey weights round differently
}

}  // namespace
}  // namespace kestrel::vo
