// Camera previews: thinned in sensor time, JPEG, and a corrupt frame refused without changing
// the thinning.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "common/error.h"
#include "common/transport/rgbd_codec.h"
#include "station/images.h"

namespace kestrel::station {
namespace {

kestrel::rgbd_frame_t frame_at(int64_t utime) {
  RgbdFrame f;
  f.utime = f.depth_utime = utime;
  f.camera.width = 64;
  f.camera.height = 48;
  f.camera.fx = f.camera.fy = 52.5;
  f.camera.cx = 31.5;
  f.camera.cy = 23.5;
  f.rgb = cv::Mat(48, 64, CV_8UC3, cv::Scalar(200, 100, 50));
  f.depth_mm = cv::Mat(48, 64, CV_16UC1, cv::Scalar(1500));
  return transport::encode_rgbd(f);
}

bool is_jpeg(const std::vector<uint8_t>& b) { return b.size() > 4 && b[0] == 0xFF && b[1] == 0xD8; }

TEST(StationImages, APreviewPerPeriodOfSensorTimeAsJpeg) {
  PreviewThinner thinner({0.5, 70, 5.0});
  const auto first = thinner.on_frame(frame_at(1'000'000), "CAMERA_RGBD");
  ASSERT_TRUE(first.has_value());
  EXPECT_TRUE(is_jpeg(first->colour_jpeg));
  EXPECT_TRUE(is_jpeg(first->depth_jpeg));
  EXPECT_FALSE(thinner.on_frame(frame_at(1'200'000), "CAMERA_RGBD").has_value());
  EXPECT_TRUE(thinner.on_frame(frame_at(1'500'000), "CAMERA_RGBD").has_value());
  // A replay started again (time going back) gives a preview at once.
  EXPECT_TRUE(thinner.on_frame(frame_at(100'000), "CAMERA_RGBD").has_value());
}

TEST(StationImages, ACorruptFrameIsRefusedAndTheNextGoodOneShown) {
  PreviewThinner thinner({0.5, 70, 5.0});
  kestrel::rgbd_frame_t bad = frame_at(1'000'000);
  bad.depth.resize(bad.depth.size() / 2);  // truncated
  bad.depth_size = static_cast<int32_t>(bad.depth.size());
  EXPECT_THROW(thinner.on_frame(bad, "CAMERA_RGBD"), InputError);
  EXPECT_TRUE(thinner.on_frame(frame_at(1'100'000), "CAMERA_RGBD").has_value());
  EXPECT_THROW(PreviewThinner({0.0, 70, 5.0}), std::invalid_argument);
  EXPECT_THROW(PreviewThinner({0.5, 0, 5.0}), std::invalid_argument);
}

TEST(StationImages, DepthIsRedNearBlueFarBlackWithoutReading) {
  cv::Mat depth(1, 4, CV_16UC1);
  depth.at<uint16_t>(0, 0) = 0;
  depth.at<uint16_t>(0, 1) = 1;
  depth.at<uint16_t>(0, 2) = 2500;
  depth.at<uint16_t>(0, 3) = 9000;
  const cv::Mat p = depth_picture(depth, 5.0);
  EXPECT_EQ(p.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(p.at<cv::Vec3b>(0, 1)[0], 254);  // R
  EXPECT_EQ(p.at<cv::Vec3b>(0, 2), cv::Vec3b(0, 255, 0));  // half way: green
  EXPECT_EQ(p.at<cv::Vec3b>(0, 3), cv::Vec3b(0, 0, 255));  // beyond far: blue
}

}  // namespace
}  // namespace kestrel::station
