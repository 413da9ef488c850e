// Patch descriptors against their definition (vo/descriptor.h): the w x w patch, mean
// (sum + n / 2) / n subtracted, + 128, saturated, the 9 x 9 patch's last pixel dropped and
// other sizes zero-padded to 16 bytes; on random patches and on flat extremes that saturate.

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "vo/descriptor.h"

namespace kestrel::vo {
namespace {

std::vector<uint8_t> expected_descriptor(const cv::Mat& image, int x, int y, int w) {
  const int bytes = descriptor_bytes(w);
  const int n = std::min(w * w, bytes);
  std::vector<int> patch;
  for (int dy = -w / 2; dy <= w / 2; ++dy)
    for (int dx = -w / 2; dx <= w / 2; ++dx) patch.push_back(image.at<uint8_t>(y + dy, x + dx));
  patch.resize(static_cast<size_t>(n));
  int sum = 0;
  for (int v : patch) sum += v;
  const int mean = (sum + n / 2) / n;
  std::vector<uint8_t> out(static_cast<size_t>(bytes), 0);
  for (int i = 0; i < n; ++i) out[static_cast<size_t>(i)] = static_cast<uint8_t>(std::clamp(patch[static_cast<size_t>(i)] - mean + 128, 0, 255));
  return out;
}

TEST(Descriptor, EqualsItsDefinitionForEveryWindowAndSaturates) {
  cv::Mat image(60, 70, CV_8UC1);
  cv::RNG(21).fill(image, cv::RNG::UNIFORM, 0, 256);
  image(cv::Rect(0, 0, 20, 20)).setTo(0);      // flat dark: mean 0, everything 128
  image(cv::Rect(50, 40, 20, 20)).setTo(255);  // flat bright
  image(cv::Rect(20, 0, 10, 30)).setTo(255);   // half bright, half noise: saturates high
  image(cv::Rect(30, 0, 10, 30)).setTo(0);
  for (int w = 3; w <= 15; w += 2) {
    DescriptorSet set;
    set.reset(w);
    std::vector<std::vector<uint8_t>> expected;
    for (int y = w / 2; y < image.rows - w / 2; y += 3) {
      for (int x = w / 2; x < image.cols - w / 2; x += 4) {
        set.add(image, x, y);
        expected.push_back(expected_descriptor(image, x, y, w));
      }
    }
    ASSERT_EQ(set.size(), static_cast<int>(expected.size()));
    for (int i = 0; i < set.size(); ++i) {
      const std::vector<uint8_t> got(set[i], set[i] + set.bytes());
      ASSERT_EQ(got, expected[static_cast<size_t>(i)]) << "window " << w << " descriptor " << i;
    }
  }
}

}  // namespace
}  // namespace kestrel::vo
