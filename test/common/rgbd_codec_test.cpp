#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "common/error.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::transport {
namespace {

RgbdFrame test_frame() {
  RgbdFrame f;
  f.utime = 1305031229528784;
  f.depth_utime = f.utime + 7000;
  f.seq = 42;
  f.sensor = "kinect1";
  f.camera.fx = 517.3;
  f.camera.fy = 516.5;
  f.camera.cx = 318.6;
  f.camera.cy = 255.3;
  f.rgb = cv::Mat(480, 640, CV_8UC3);
  f.depth_mm = cv::Mat(480, 640, CV_16UC1);
  std::mt19937 rng(1);
  // Smooth colour (JPEG-friendly) and a depth ramp with holes.
  for (int r = 0; r < 480; ++r) {
    for (int c = 0; c < 640; ++c) {
      f.rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(r / 2, c / 3, (r + c) / 5);
      f.depth_mm.at<uint16_t>(r, c) = (rng() % 50 == 0) ? 0 : static_cast<uint16_t>(500 + r * 7 + c);
    }
  }
  return f;
}

TEST(RgbdCodec, RawRoundTripIsExact) {
  const RgbdFrame f = test_frame();
  const auto m = encode_rgbd(f);
  EXPECT_EQ(m.rgb_encoding, kestrel::rgbd_frame_t::RGB_RGB8);
  EXPECT_EQ(m.rgb_size, 640 * 480 * 3);
  // Wire order is R, G, B.
  EXPECT_EQ(m.rgb[0], f.rgb.at<cv::Vec3b>(0, 0)[0]);
  const RgbdFrame g = decode_rgbd(m, "test");
  EXPECT_EQ(g.utime, f.utime);
  EXPECT_EQ(g.depth_utime, f.depth_utime);
  EXPECT_EQ(g.seq, 42);
  EXPECT_EQ(g.sensor, "kinect1");  // the consumers' profile is keyed by it
  EXPECT_DOUBLE_EQ(g.camera.fx, 517.3);
  EXPECT_EQ(cv::norm(g.rgb, f.rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(g.depth_mm, f.depth_mm, cv::NORM_INF), 0.0);
}

TEST(RgbdCodec, CompressedDepthIsLosslessAndColourClose) {
  const RgbdFrame f = test_frame();
  RgbdEncoding enc;
  enc.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  enc.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  const auto m = encode_rgbd(f, enc);
  EXPECT_LT(m.rgb_size, 640 * 480 * 3 / 5);
  EXPECT_LT(m.depth_size, 640 * 480 * 2);
  const RgbdFrame g = decode_rgbd(m, "test");
  EXPECT_EQ(cv::norm(g.depth_mm, f.depth_mm, cv::NORM_INF), 0.0);
  cv::Mat diff;
  cv::absdiff(g.rgb, f.rgb, diff);
  EXPECT_LT(cv::mean(diff)[0], 2.0);
}

TEST(RgbdCodec, WrongSizesAndCorruptDataAreInputErrors) {
  const RgbdFrame f = test_frame();
  auto m = encode_rgbd(f);
  m.rgb.pop_back();
  m.rgb_size--;
  EXPECT_THROW(decode_rgbd(m, "CAMERA_RGBD"), InputError);

  m = encode_rgbd(f);
  m.camera.width = 320;  // depth no longer matches
  EXPECT_THROW(decode_rgbd(m, "CAMERA_RGBD"), InputError);

  RgbdEncoding enc;
  enc.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  enc.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  m = encode_rgbd(f, enc);
  for (size_t i = 0; i < m.depth.size(); i += 7) m.depth[i] ^= 0x5a;
  EXPECT_THROW(decode_rgbd(m, "CAMERA_RGBD"), InputError);

  m = encode_rgbd(f, enc);
  m.rgb.resize(m.rgb.size() / 3);
  m.rgb_size = static_cast<int32_t>(m.rgb.size());
  std::fill(m.rgb.begin(), m.rgb.begin() + 20, 0);
  EXPECT_THROW(decode_rgbd(m, "CAMERA_RGBD"), InputError);

  m = encode_rgbd(f);
  m.depth_encoding = 99;
  try {
    decode_rgbd(m, "CAMERA_RGBD");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "CAMERA_RGBD: unknown depth encoding 99");
  }

  m = encode_rgbd(f);
  m.camera.fx = std::nan("");
  EXPECT_THROW(decode_rgbd(m, "CAMERA_RGBD"), InputError);
}

TEST(RgbdCodec, DepthOnlyAndColourOnlyFrames) {
  RgbdFrame f = test_frame();
  f.rgb.release();
  auto g = decode_rgbd(encode_rgbd(f), "test");
  EXPECT_TRUE(g.rgb.empty());
  EXPECT_FALSE(g.depth_mm.empty());
  f = test_frame();
  f.depth_mm.release();
  g = decode_rgbd(encode_rgbd(f), "test");
  EXPECT_TRUE(g.depth_mm.empty());
}

TEST(DepthConversion, MillimetresAndMetres) {
  cv::Mat mm = (cv::Mat_<uint16_t>(1, 3) << 0, 1000, 65535);
  const cv::Mat m = depth_to_metres(mm);
  EXPECT_TRUE(std::isnan(m.at<float>(0, 0)));
  EXPECT_FLOAT_EQ(m.at<float>(0, 1), 1.0f);
  cv::Mat metres = (cv::Mat_<float>(1, 5) << std::nanf(""), -1.0f, 0.0004f, 1.2344f, 100.0f);
  const cv::Mat back = depth_to_millimetres(metres);
  EXPECT_EQ(back.at<uint16_t>(0, 0), 0);
  EXPECT_EQ(back.at<uint16_t>(0, 1), 0);
  EXPECT_EQ(back.at<uint16_t>(0, 2), 0);
  EXPECT_EQ(back.at<uint16_t>(0, 3), 1234);
  EXPECT_EQ(back.at<uint16_t>(0, 4), 0);  // beyond the uint16 range: no reading
}

}  // namespace
}  // namespace kestrel::transport
