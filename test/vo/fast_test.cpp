// FAST-9 against OpenCV's cv::FAST (TYPE_9_16) on the same images: the same corners with the
// same scores, with and without non-maximum suppression, on the SSE2 and the scalar paths.

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "test/vo/synthetic_scene.h"
#include "vo/fast.h"

namespace kestrel::vo {
namespace {

cv::Mat scene_image() {
  const test::SyntheticScene scene(3);
  const RgbdFrame f = scene.render(Eigen::Isometry3d::Identity(), test::test_camera(), 1);
  cv::Mat grey;
  cv::cvtColor(f.rgb, grey, cv::COLOR_RGB2GRAY);
  return grey;
}

cv::Mat noise_image(int width, int height, unsigned seed) {
  cv::Mat m(height, width, CV_8UC1);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(0, 255);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) m.at<uint8_t>(y, x) = static_cast<uint8_t>(value(rng));
  cv::GaussianBlur(m, m, cv::Size(3, 3), 0.8);
  return m;
}

void expect_same_as_opencv(const cv::Mat& image, int threshold, bool nonmax) {
  std::vector<cv::KeyPoint> reference;
  cv::FAST(image, reference, threshold, nonmax, cv::FastFeatureDetector::TYPE_9_16);
  std::sort(reference.begin(), reference.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
    return a.pt.y != b.pt.y ? a.pt.y < b.pt.y : a.pt.x < b.pt.x;
  });
  std::vector<FastCorner> simd, scalar;
  FastScratch scratch;
  detect_fast9(image, threshold, nonmax, simd, scratch);
  detect_fast9_scalar(image, threshold, nonmax, scalar, scratch);
  ASSERT_GT(reference.size(), 50u) << "the image should have corners at threshold " << threshold;
  ASSERT_EQ(simd.size(), reference.size()) << "threshold " << threshold << " nonmax " << nonmax;
  ASSERT_EQ(scalar.size(), reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    EXPECT_EQ(simd[i].x, int(reference[i].pt.x)) << i;
    EXPECT_EQ(simd[i].y, int(reference[i].pt.y)) << i;
    EXPECT_EQ(scalar[i].x, simd[i].x) << i;
    EXPECT_EQ(scalar[i].y, simd[i].y) << i;
    EXPECT_EQ(scalar[i].score, simd[i].score) << i;
    if (nonmax) {
      EXPECT_EQ(simd[i].score, int(reference[i].response)) << i;
    }
  }
}

TEST(Fast, MatchesOpenCvOnTheSyntheticScene) {
  const cv::Mat image = scene_image();
  for (int t : {10, 20, 40}) {
    expect_same_as_opencv(image, t, true);
    expect_same_as_opencv(image, t, false);
  }
}

TEST(Fast, MatchesOpenCvOnNoiseOfOddWidth) {
  // An odd width exercises the scalar tail after the 16-pixel SSE2 blocks.
  const cv::Mat image = noise_image(203, 97, 5);
  for (int t : {5, 15, 30}) expect_same_as_opencv(image, t, true);
}

TEST(Fast, SimdCornersAndScoresEqualTheScalarOnesAtAnyThreshold) {
  // The SSE2 path scores 16 pixels at once in saturating bytes; the scalar one calls
  // fast9_score() per corner. Raw (unblurred) noise of full contrast has corners up to the
  // highest thresholds; an odd width and a region of interest (row stride != width) too.
  cv::Mat raw(61, 150, CV_8UC1);
  cv::RNG(3).fill(raw, cv::RNG::UNIFORM, 0, 256);
  raw.at<uint8_t>(30, 40) = 255;
  raw.at<uint8_t>(30, 60) = 0;
  const cv::Mat roi = raw(cv::Rect(2, 1, 133, 59));
  for (int t : {1, 2, 17, 60, 128, 200, 254}) {
    for (bool nonmax : {false, true}) {
      std::vector<FastCorner> simd, scalar;
      FastScratch scratch;
      detect_fast9(roi, t, nonmax, simd, scratch);
      detect_fast9_scalar(roi, t, nonmax, scalar, scratch);
      ASSERT_EQ(simd.size(), scalar.size()) << "threshold " << t << " nonmax " << nonmax;
      for (size_t i = 0; i < simd.size(); ++i) {
        ASSERT_EQ(simd[i].x, scalar[i].x) << t << " " << i;
        ASSERT_EQ(simd[i].y, scalar[i].y) << t << " " << i;
        ASSERT_EQ(simd[i].score, scalar[i].score) << t << " " << i;
        ASSERT_EQ(simd[i].score, fast9_score(roi.ptr<uint8_t>(simd[i].y) + simd[i].x, int(roi.step[0])));
        ASSERT_GE(simd[i].score, t);
      }
      if (t <= 60) {
        EXPECT_GT(simd.size(), 10u) << "threshold " << t;
      }
    }
  }
}

TEST(Fast, ExtremeIntensitiesSaturateLikeTheScalarTest) {
  // A white dot on black and a black dot on white are corners at any threshold below 255.
  cv::Mat image(32, 48, CV_8UC1, cv::Scalar(0));
  image.at<uint8_t>(10, 20) = 255;
  cv::Mat inverted = 255 - image;
  for (const cv::Mat& m : {image, inverted}) {
    std::vector<FastCorner> corners;
    FastScratch scratch;
    detect_fast9(m, 254, true, corners, scratch);
    ASSERT_EQ(corners.size(), 1u);
    EXPECT_EQ(corners[0].x, 20);
    EXPECT_EQ(corners[0].y, 10);
    EXPECT_EQ(corners[0].score, 254);
  }
}

TEST(Fast, RejectsWrongTypeAndThreshold) {
  std::vector<FastCorner> corners;
  FastScratch scratch;
  EXPECT_THROW(detect_fast9(cv::Mat(20, 20, CV_8UC3), 10, true, corners, scratch), std::invalid_argument);
  EXPECT_THROW(detect_fast9(cv::Mat(20, 20, CV_8UC1), 0, true, corners, scratch), std::invalid_argument);
  detect_fast9(cv::Mat(5, 5, CV_8UC1, cv::Scalar(7)), 10, true, corners, scratch);
  EXPECT_TRUE(corners.empty());
}

}  // namespace
}  // namespace kestrel::vo
