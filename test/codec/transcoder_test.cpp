// RgbdTranscoder against known answers: depth survives every path bit for bit, colour
// survives raw paths bit for bit and JPEG within a known error, components already in the
// target encoding are passed through untouched, and every corrupt frame is rejected.

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

#include "common/error.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "test/replay/fixtures.h"
#include "tools/codec/transcoder.h"

namespace kestrel::codec {
namespace {

using kestrel::rgbd_frame_t;
using transport::RgbdEncoding;

RgbdEncoding encoding(int8_t rgb, int8_t depth, int quality = 90) {
  RgbdEncoding e;
  e.rgb = rgb;
  e.depth = depth;
  e.jpeg_quality = quality;
  return e;
}
const RgbdEncoding kRaw = encoding(rgbd_frame_t::RGB_RGB8, rgbd_frame_t::DEPTH_U16_MM);
const RgbdEncoding kCompressed = encoding(rgbd_frame_t::RGB_JPEG, rgbd_frame_t::DEPTH_U16_MM_ZSTD);

bool same_pixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(RgbdTranscoder, CompressesLosslessDepthAndCloseColour) {
  const RgbdFrame frame = test::synthetic_frame(3, 64, 48);
  const rgbd_frame_t raw = transport::encode_rgbd(frame, kRaw);
  RgbdTranscoder compress(kCompressed);
  const rgbd_frame_t z = compress.transcode(raw, "IN");

  EXPECT_EQ(z.rgb_encoding, rgbd_frame_t::RGB_JPEG);
  EXPECT_EQ(z.depth_encoding, rgbd_frame_t::DEPTH_U16_MM_ZSTD);
  EXPECT_LT(z.getEncodedSize(), raw.getEncodedSize());
  EXPECT_EQ(z.utime, raw.utime);
  EXPECT_EQ(z.depth_utime, raw.depth_utime);
  EXPECT_EQ(z.seq, raw.seq);
  EXPECT_EQ(transport::encode_message(z.camera), transport::encode_message(raw.camera));

  const RgbdFrame back = transport::decode_rgbd(z, "Z");
  EXPECT_TRUE(same_pixels(back.depth_mm, frame.depth_mm));
  // Pseudo-random chroma texture with 4:2:0 subsampling is JPEG's worst case (about 25 dB
  // here); it must still be a faithful picture, not garbage (which would be below 10 dB).
  EXPECT_GT(cv::PSNR(back.rgb, frame.rgb), 23.0);
  EXPECT_EQ(compress.stats().frames, 1);
  EXPECT_EQ(compress.stats().bytes_in, raw.getEncodedSize());
  EXPECT_EQ(compress.stats().bytes_out, z.getEncodedSize());
}

TEST(RgbdTranscoder, JpegKeepsASmoothImageClose) {
  RgbdFrame frame = test::synthetic_frame(0, 64, 48);
  for (int y = 0; y < frame.rgb.rows; ++y)
    for (int x = 0; x < frame.rgb.cols; ++x)
      frame.rgb.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uint8_t>(2 * x), static_cast<uint8_t>(3 * y), 128);
  RgbdTranscoder compress(kCompressed);
  const RgbdFrame back = transport::decode_rgbd(compress.transcode(transport::encode_rgbd(frame, kRaw), "IN"), "Z");
  EXPECT_GT(cv::PSNR(back.rgb, frame.rgb), 38.0);
}

TEST(RgbdTranscoder, ExpandsBackToRawExactlyAsDecoded) {
  const rgbd_frame_t raw = transport::encode_rgbd(test::synthetic_frame(5), kRaw);
  RgbdTranscoder compress(kCompressed), expand(kRaw);
  const rgbd_frame_t z = compress.transcode(raw, "IN");
  const rgbd_frame_t again = expand.transcode(z, "Z");
  EXPECT_EQ(again.rgb_encoding, rgbd_frame_t::RGB_RGB8);
  EXPECT_EQ(again.depth_encoding, rgbd_frame_t::DEPTH_U16_MM);
  EXPECT_EQ(again.depth, raw.depth);  // lossless both ways
  const RgbdFrame decoded_z = transport::decode_rgbd(z, "Z");
  EXPECT_TRUE(same_pixels(transport::decode_rgbd(again, "RAW").rgb, decoded_z.rgb));
}

TEST(RgbdTranscoder, PassesThroughComponentsAlreadyInTheTargetEncoding) {
  const RgbdFrame frame = test::synthetic_frame(7);
  const rgbd_frame_t jpeg_raw =
      transport::encode_rgbd(frame, encoding(rgbd_frame_t::RGB_JPEG, rgbd_frame_t::DEPTH_U16_MM, 75));
  RgbdTranscoder to_compressed(kCompressed);  // quality 90: a re-encode would change the bytes
  const rgbd_frame_t out = to_compressed.transcode(jpeg_raw, "IN");
  EXPECT_EQ(out.rgb, jpeg_raw.rgb);
  EXPECT_EQ(out.depth_encoding, rgbd_frame_t::DEPTH_U16_MM_ZSTD);

  // Everything already as wanted: the message comes out byte for byte.
  const rgbd_frame_t twice = to_compressed.transcode(out, "OUT");
  EXPECT_EQ(transport::encode_message(twice), transport::encode_message(out));
}

TEST(RgbdTranscoder, KeepsAMissingComponentMissing) {
  RgbdFrame depth_only = test::synthetic_frame(1);
  depth_only.rgb.release();
  const rgbd_frame_t in = transport::encode_rgbd(depth_only, kRaw);
  RgbdTranscoder compress(kCompressed);
  const rgbd_frame_t out = compress.transcode(in, "IN");
  EXPECT_EQ(out.rgb_encoding, rgbd_frame_t::RGB_NONE);
  EXPECT_EQ(out.rgb_size, 0);
  EXPECT_EQ(out.depth_encoding, rgbd_frame_t::DEPTH_U16_MM_ZSTD);

  RgbdFrame colour_only = test::synthetic_frame(1);
  colour_only.depth_mm.release();
  const rgbd_frame_t out2 = compress.transcode(transport::encode_rgbd(colour_only, kRaw), "IN");
  EXPECT_EQ(out2.depth_encoding, rgbd_frame_t::DEPTH_NONE);
  EXPECT_EQ(out2.rgb_encoding, rgbd_frame_t::RGB_JPEG);
}

// Each corruption must be rejected with the channel named, and not counted as transcoded.
TEST(RgbdTranscoder, RejectsCorruptFramesNamingTheChannel) {
  const rgbd_frame_t good = transport::encode_rgbd(test::synthetic_frame(2), kRaw);
  const rgbd_frame_t good_z = RgbdTranscoder(kCompressed).transcode(good, "IN");
  std::vector<std::pair<std::string, rgbd_frame_t>> bad;
  auto add = [&](const std::string& what, const rgbd_frame_t& base, auto&& damage) {
    rgbd_frame_t m = base;
    damage(m);
    bad.emplace_back(what, m);
  };
  add("short colour", good, [](rgbd_frame_t& m) { m.rgb.resize(10), m.rgb_size = 10; });
  add("short depth", good, [](rgbd_frame_t& m) { m.depth.pop_back(), m.depth_size -= 1; });
  add("unknown colour encoding", good, [](rgbd_frame_t& m) { m.rgb_encoding = 9; });
  add("unknown depth encoding", good, [](rgbd_frame_t& m) { m.depth_encoding = 9; });
  add("NaN focal length", good, [](rgbd_frame_t& m) { m.camera.fx = std::nan(""); });
  add("zero-sized camera", good, [](rgbd_frame_t& m) { m.camera.width = 0; });
  add("neither image", good, [](rgbd_frame_t& m) {
    m.rgb_encoding = rgbd_frame_t::RGB_NONE, m.rgb.clear(), m.rgb_size = 0;
    m.depth_encoding = rgbd_frame_t::DEPTH_NONE, m.depth.clear(), m.depth_size = 0;
  });
  add("corrupt JPEG", good_z, [](rgbd_frame_t& m) {
    for (size_t i = 0; i < 16; ++i) m.rgb[i] = 0;
  });
  add("corrupt zstd", good_z, [](rgbd_frame_t& m) {
    for (size_t i = m.depth.size() / 2; i < m.depth.size(); ++i) m.depth[i] ^= 0x5a;
  });
  add("non-unit camera mounting", good, [](rgbd_frame_t& m) { m.camera.T_body_camera.orientation[0] = 3; });

  RgbdTranscoder expand(kRaw), compress(kCompressed);
  for (const auto& [what, m] : bad) {
    for (RgbdTranscoder* t : {&expand, &compress}) {
      try {
        t->transcode(m, "CAMERA_RGBD");
        ADD_FAILURE() << what << ": accepted";
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("CAMERA_RGBD: ", 0), 0u) << what << ": " << e.what();
      }
    }
  }
  EXPECT_EQ(expand.stats().frames, 0);
  EXPECT_EQ(compress.stats().frames, 0);
}

TEST(RgbdTranscoder, RejectsImpossibleTargets) {
  EXPECT_THROW(RgbdTranscoder(encoding(rgbd_frame_t::RGB_NONE, rgbd_frame_t::DEPTH_U16_MM)),
               std::invalid_argument);
  EXPECT_THROW(RgbdTranscoder(encoding(rgbd_frame_t::RGB_RGB8, rgbd_frame_t::DEPTH_NONE)),
               std::invalid_argument);
  EXPECT_THROW(RgbdTranscoder(encoding(rgbd_frame_t::RGB_JPEG, rgbd_frame_t::DEPTH_U16_MM, 0)),
               std::invalid_argument);
  RgbdEncoding e = kCompressed;
  e.zstd_level = 20;
  EXPECT_THROW(RgbdTranscoder{e}, std::invalid_argument);
}

TEST(RgbdTranscoder, ResetForgetsTheStatistics) {
  RgbdTranscoder t(kCompressed);
  t.transcode(transport::encode_rgbd(test::synthetic_frame(0), kRaw), "IN");
  ASSERT_EQ(t.stats().frames, 1);
  t.reset();
  EXPECT_EQ(t.stats().frames, 0);
  EXPECT_EQ(t.stats().bytes_in, 0);
  EXPECT_EQ(t.stats().bytes_out, 0);
}

}  // namespace
}  // namespace kestrel::codec

namespace kestrel::codec {
namespace {

TEST(FrameRateLimit, ThinsA30HzCameraToEveryThirdFrameDespiteJitter) {
  FrameRateLimit limit(10.0);
  std::vector<int> kept;
  for (int i = 0; i < 12; ++i) {
    const int64_t jitter = (i % 2 == 0) ? 2000 : -2000;  // +-2 ms on 33.3 ms
    if (limit.keep(1'000'000 + i * 33'333 + jitter)) kept.push_back(i);
  }
  EXPECT_EQ(kept, (std::vector<int>{0, 3, 6, 9}));
}

TEST(FrameRateLimit, ZeroKeepsEveryFrameAndAStampBackInTimeStartsAgain) {
  FrameRateLimit all(0.0);
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(all.keep(i));
  FrameRateLimit limit(1.0);
  EXPECT_TRUE(limit.keep(5'000'000));
  EXPECT_FALSE(limit.keep(5'500'000));
  EXPECT_TRUE(limit.keep(1'000'000));  // a restarted source
  EXPECT_FALSE(limit.keep(1'100'000));
  limit.reset();
  EXPECT_TRUE(limit.keep(1'100'000));
  EXPECT_THROW(FrameRateLimit(-1.0), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::codec
