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

TEST(Pyramid, GreyConversionEqualsTheScalarFormulaOnRandomImagesOfAnyWidth) {
  cv::RNG rng(11);
  // Widths below, at and around the 32-pixel SIMD block, odd ones, and VGA; a region of
  // interest so that rows are not contiguous.
  for (int w : {1, 7, 31, 32, 33, 63, 64, 65, 97, 641}) {
    cv::Mat big(5, w + 3, CV_8UC3);
    rng.fill(big, cv::RNG::UNIFORM, 0, 256);
    big.at<cv::Vec3b>(0, 0) = cv::Vec3b(255, 255, 255);  // the largest sum, 65408
    const cv::Mat rgb = big(cv::Rect(1, 0, w, 5));
    cv::Mat fast, scalar;
    rgb_to_grey(rgb, fast);
    rgb_to_grey_scalar(rgb, scalar);
    ASSERT_EQ(fast.size(), rgb.size());
    ASSERT_EQ(fast.type(), CV_8UC1);
    EXPECT_EQ(cv::countNonZero(fast != scalar), 0) << "width " << w;
    for (int y = 0; y < rgb.rows; ++y) {
      for (int x = 0; x < w; ++x) {
        const cv::Vec3b p = rgb.at<cv::Vec3b>(y, x);
        ASSERT_EQ(int(fast.at<uint8_t>(y, x)), (77 * p[0] + 150 * p[1] + 29 * p[2] + 128) >> 8)
            << "width " << w << " at " << x << "," << y;
      }
    }
  }
  cv::Mat white(1, 40, CV_8UC3, cv::Scalar(255, 255, 255)), grey;
  rgb_to_grey(white, grey);
  EXPECT_EQ(cv::countNonZero(grey != 255), 0);
}

TEST(Pyramid, HalvingEqualsTheScalarLoopsForAnySize) {
  // half_size's SSE2 blocks of 8 outputs and its scalar tail against the scalar reference,
  // for widths around the block edges (16 + 16 k), odd and tiny sizes, and extreme values.
  cv::RNG rng(13);
  std::vector<uint16_t> row;
  for (int w : {1, 2, 3, 15, 16, 17, 18, 31, 32, 33, 34, 47, 48, 49, 50, 81, 640, 641}) {
    for (int h : {1, 2, 5, 8}) {
      cv::Mat in(h, w, CV_8UC1);
      rng.fill(in, cv::RNG::UNIFORM, 0, 256);
      if (w > 4) in.row(0).colRange(0, w / 2).setTo(255);  // the largest sums
      cv::Mat fast, scalar;
      half_size(in, fast, row);
      half_size_scalar(in, scalar, row);
      ASSERT_EQ(fast.size(), cv::Size((w + 1) / 2, (h + 1) / 2));
      ASSERT_EQ(scalar.size(), fast.size());
      EXPECT_EQ(cv::countNonZero(fast != scalar), 0) << w << "x" << h;
      if (w >= 5 && h >= 5) {
        cv::Mat reference;
        cv::pyrDown(in, reference);
        EXPECT_EQ(cv::countNonZero(reference != fast), 0) << w << "x" << h << " against cv::pyrDown";
      }
    }
  }
}

TEST(Pyramid, BlurOfAnImpulseIsTheRoundedSeparableKernel) {
  // Known answer of the integer filter: the horizontal pass gives (8 + k[dx] * 255) >> 4 on
  // the impulse's row (0 elsewhere), the vertical one (128 + k[dy] * that) >> 8.
  std::vector<int> k;
  gaussian_kernel_64(0.85, k);
  const int r = static_cast<int>(k.size() / 2);
  cv::Mat grey(21, 23, CV_8UC1, cv::Scalar(0));
  grey.at<uint8_t>(10, 11) = 255;
  ImagePyramid pyramid;
  pyramid.build(grey, 1, 0.85);
  const cv::Mat& out = pyramid.level(0);
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      const int dx = x - 11, dy = y - 10;
      int expected = 0;
      if (std::abs(dx) <= r && std::abs(dy) <= r) {
        const int h = (8 + k[static_cast<size_t>(dx + r)] * 255) >> 4;
        expected = (128 + k[static_cast<size_t>(dy + r)] * h) >> 8;
      }
      ASSERT_EQ(int(out.at<uint8_t>(y, x)), expected) << x << "," << y;
    }
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
