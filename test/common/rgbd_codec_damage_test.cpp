// Damaged RGB-D messages (issue 38, "one bad compressed frame blinds the consumers"): every
// damage is an InputError naming the channel, and the good frame after it decodes exactly as
// it does alone, for each encoding. Before the fix, one JPEG whose header read failed part-way
// left the thread's TurboJPEG handle failing every later frame the same way.

#include <gtest/gtest.h>

#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "common/error.h"
#include "common/numbers.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::transport {
namespace {

using kestrel::rgbd_frame_t;

constexpr const char* kChannel = "CAMERA_RGBD";

// Small (fast to decode a thousand times), with smooth colour, texture and depth holes, so
// that JPEG and zstd both have real tables and blocks to damage.
RgbdFrame small_frame() {
  RgbdFrame f;
  f.utime = 1'000'000;
  f.depth_utime = f.utime + 5'000;
  f.seq = 7;
  f.sensor = "simulator";
  f.camera.width = 64;
  f.camera.height = 48;
  f.camera.fx = f.camera.fy = 60.0;
  f.camera.cx = 31.5;
  f.camera.cy = 23.5;
  f.rgb.create(48, 64, CV_8UC3);
  f.depth_mm.create(48, 64, CV_16UC1);
  std::mt19937 rng(3);
  for (int r = 0; r < 48; ++r) {
    for (int c = 0; c < 64; ++c) {
      f.rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(r * 5, c * 4, static_cast<uint8_t>((r * c) % 251));
      f.depth_mm.at<uint16_t>(r, c) = rng() % 17 == 0 ? 0 : static_cast<uint16_t>(800 + 13 * r + c + rng() % 9);
    }
  }
  return f;
}

RgbdEncoding compressed() {
  RgbdEncoding e;
  e.rgb = rgbd_frame_t::RGB_JPEG;
  e.depth = rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  return e;
}

// The message decoded on a thread of its own, i.e. with decoder state no other decode touched.
RgbdFrame decode_alone(const rgbd_frame_t& m) {
  RgbdFrame out;
  std::exception_ptr error;
  std::thread([&] {
    try {
      out = decode_rgbd(m, "alone");
    } catch (...) {
      error = std::current_exception();
    }
  }).join();
  if (error) std::rethrow_exception(error);
  return out;
}

bool same_image(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty();
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Decodes `damaged` (which may be accepted only if `may_decode`: a flipped bit inside zstd
// literals or JPEG entropy data can yield another valid image) and then `good`, which must come
// out exactly as `reference`. Returns false, with a test failure naming `what`, otherwise.
bool damaged_then_good(const rgbd_frame_t& damaged, const rgbd_frame_t& good, const RgbdFrame& reference,
                       const std::string& what, bool may_decode) {
  try {
    decode_rgbd(damaged, kChannel);
    if (!may_decode) {
      ADD_FAILURE() << what << ": accepted";
      return false;
    }
  } catch (const InputError& e) {
    if (std::string(e.what()).rfind(std::string(kChannel) + ": ", 0) != 0) {
      ADD_FAILURE() << what << ": the error does not name the channel: " << e.what();
      return false;
    }
  }
  try {
    const RgbdFrame g = decode_rgbd(good, kChannel);
    if (!same_image(g.rgb, reference.rgb) || !same_image(g.depth_mm, reference.depth_mm)) {
      ADD_FAILURE() << what << ": the good frame after it decodes differently";
      return false;
    }
  } catch (const InputError& e) {
    ADD_FAILURE() << what << ": the good frame after it is rejected: " << e.what();
    return false;
  }
  return true;
}

// Applies `damage` to a copy of `good` once per position 0 .. n-1; stops at the first failure.
void for_each_position(const rgbd_frame_t& good, size_t n, const std::string& name, bool may_decode,
                       const std::function<void(rgbd_frame_t&, size_t)>& damage) {
  const RgbdFrame reference = decode_alone(good);
  for (size_t i = 0; i < n; ++i) {
    rgbd_frame_t m = good;
    damage(m, i);
    if (!damaged_then_good(m, good, reference, name + " at " + std::to_string(i), may_decode)) return;
  }
}

std::vector<uint8_t> random_bytes(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> b(n);
  for (auto& x : b) x = static_cast<uint8_t>(rng());
  return b;
}

TEST(RgbdCodecDamage, EveryFlippedJpegByteLeavesTheNextFrameIntact) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  ASSERT_GT(good.rgb.size(), 600u);  // the tables alone are ~600 bytes: the damage hits them all
  for (uint8_t pattern : {uint8_t{0xff}, uint8_t{0x01}, uint8_t{0x80}}) {
    for_each_position(good, good.rgb.size(), "JPEG byte xor " + std::to_string(pattern), true,
                      [&](rgbd_frame_t& m, size_t i) { m.rgb[i] ^= pattern; });
  }
}

TEST(RgbdCodecDamage, EveryTruncatedJpegIsRejectedAndTheNextFrameIntact) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  for_each_position(good, good.rgb.size(), "JPEG cut to", false, [](rgbd_frame_t& m, size_t n) {
    m.rgb.resize(n);
    m.rgb_size = static_cast<int32_t>(n);
  });
}

TEST(RgbdCodecDamage, GarbageJpegIsRejectedAndTheNextFrameIntact) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  const RgbdFrame reference = decode_alone(good);
  std::vector<std::pair<std::string, std::vector<uint8_t>>> payloads = {
      {"empty", {}}, {"one byte", {0xff}}, {"SOI only", {0xff, 0xd8}}, {"SOI EOI", {0xff, 0xd8, 0xff, 0xd9}}};
  for (size_t n : {3u, 64u, 1000u, 20000u}) payloads.emplace_back("random " + std::to_string(n), random_bytes(n, n));
  std::vector<uint8_t> soi_then_noise = {0xff, 0xd8, 0xff, 0xdb};
  const auto noise = random_bytes(900, 9);
  soi_then_noise.insert(soi_then_noise.end(), noise.begin(), noise.end());
  payloads.emplace_back("SOI, DQT marker, noise", soi_then_noise);
  // The good stream's tables followed by another stream's scan: headers valid, data not.
  std::vector<uint8_t> spliced(good.rgb.begin(), good.rgb.begin() + good.rgb.size() / 2);
  spliced.insert(spliced.end(), noise.begin(), noise.end());
  payloads.emplace_back("tables then noise", spliced);
  for (const auto& [name, bytes] : payloads) {
    rgbd_frame_t m = good;
    m.rgb = bytes;
    m.rgb_size = static_cast<int32_t>(bytes.size());
    damaged_then_good(m, good, reference, name, false);
  }
}

TEST(RgbdCodecDamage, JpegOfAnotherSizeIsRejectedNamingBoth) {
  const RgbdFrame f = small_frame();
  const rgbd_frame_t good = encode_rgbd(f, compressed());
  const RgbdFrame reference = decode_alone(good);
  RgbdFrame transposed = f;
  transposed.camera.width = 48;
  transposed.camera.height = 64;
  transposed.rgb = f.rgb.t();
  transposed.depth_mm = f.depth_mm.t();
  rgbd_frame_t m = good;
  m.rgb = encode_rgbd(transposed, compressed()).rgb;  // same pixel count, other shape
  m.rgb_size = static_cast<int32_t>(m.rgb.size());
  try {
    decode_rgbd(m, kChannel);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "CAMERA_RGBD: JPEG is 48x64 but the camera is 64x48");
  }
  damaged_then_good(m, good, reference, "transposed JPEG", false);
}

// The mapper's path: JPEG colour checked now, decoded later. The colour comes out as
// decode_rgbd's; every truncation fails at one of the two steps, naming the channel, and the
// good frame after it is intact; raw colour is not deferred.
TEST(RgbdCodecDamage, DeferredColourIsTheSameImageAndEveryTruncatedJpegFailsAtOneStep) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  const RgbdFrame reference = decode_alone(good);
  const RgbdDeferredColour d = decode_rgbd_deferring_colour(good, kChannel);
  EXPECT_TRUE(d.frame.rgb.empty());
  EXPECT_TRUE(same_image(d.frame.depth_mm, reference.depth_mm));
  ASSERT_TRUE(d.colour);
  EXPECT_TRUE(same_image(d.colour(), reference.rgb));
  EXPECT_TRUE(same_image(d.colour(), reference.rgb)) << "a second call";
  auto names_the_channel = [](const InputError& e) {
    return std::string(e.what()).rfind(std::string(kChannel) + ": ", 0) == 0;
  };
  int at_once = 0, later = 0;
  for (size_t n = 0; n < good.rgb.size(); ++n) {
    rgbd_frame_t m = good;
    m.rgb.resize(n);
    m.rgb_size = static_cast<int32_t>(n);
    try {
      const RgbdDeferredColour cut = decode_rgbd_deferring_colour(m, kChannel);
      ASSERT_TRUE(cut.colour);
      try {
        cut.colour();
        ADD_FAILURE() << "JPEG cut to " << n << " bytes decoded";
        break;
      } catch (const InputError& e) {
        ++later;
        ASSERT_TRUE(names_the_channel(e)) << e.what();
      }
    } catch (const InputError& e) {
      ++at_once;
      ASSERT_TRUE(names_the_channel(e)) << e.what();
    }
    ASSERT_TRUE(same_image(decode_rgbd_deferring_colour(good, kChannel).colour(), reference.rgb)) << "after " << n;
  }
  EXPECT_GT(at_once, 0) << "a cut header fails at once";
  EXPECT_GT(later, 0) << "a cut scan fails when the colour is made";
  RgbdEncoding raw = compressed();
  raw.rgb = rgbd_frame_t::RGB_RGB8;
  const RgbdDeferredColour r = decode_rgbd_deferring_colour(encode_rgbd(small_frame(), raw), kChannel);
  EXPECT_FALSE(r.colour);
  EXPECT_TRUE(same_image(r.frame.rgb, small_frame().rgb));
}

TEST(RgbdCodecDamage, EveryFlippedZstdByteLeavesTheNextFrameIntact) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  for_each_position(good, good.depth.size(), "zstd byte xor 0xff", true,
                    [](rgbd_frame_t& m, size_t i) { m.depth[i] ^= 0xff; });
}

TEST(RgbdCodecDamage, EveryTruncatedOrExtendedZstdIsRejected) {
  const rgbd_frame_t good = encode_rgbd(small_frame(), compressed());
  for_each_position(good, good.depth.size(), "zstd cut to", false, [](rgbd_frame_t& m, size_t n) {
    m.depth.resize(n);
    m.depth_size = static_cast<int32_t>(n);
  });
  const RgbdFrame reference = decode_alone(good);
  for (size_t extra : {1u, 4u, 100u}) {
    rgbd_frame_t m = good;
    const auto tail = random_bytes(extra, static_cast<uint32_t>(extra));
    m.depth.insert(m.depth.end(), tail.begin(), tail.end());
    m.depth_size = static_cast<int32_t>(m.depth.size());
    damaged_then_good(m, good, reference, "zstd with " + std::to_string(extra) + " bytes appended", false);
  }
  // A second, complete frame appended: more depth than the camera has pixels.
  rgbd_frame_t twice = good;
  twice.depth.insert(twice.depth.end(), good.depth.begin(), good.depth.end());
  twice.depth_size = static_cast<int32_t>(twice.depth.size());
  damaged_then_good(twice, good, reference, "two zstd frames", false);
  for (size_t n : {0u, 3u, 64u, 5000u}) {
    rgbd_frame_t m = good;
    m.depth = random_bytes(n, static_cast<uint32_t>(n + 1));
    m.depth_size = static_cast<int32_t>(n);
    damaged_then_good(m, good, reference, "random zstd " + std::to_string(n), false);
  }
}

TEST(RgbdCodecDamage, RawPayloadsOfTheWrongSizeAreRejected) {
  const rgbd_frame_t good = encode_rgbd(small_frame());
  const RgbdFrame reference = decode_alone(good);
  for (long delta : {-1L, 1L, -64L * 3, 64L * 3, -64L * 48 * 3 / 2}) {
    rgbd_frame_t m = good;
    m.rgb.resize(static_cast<size_t>(static_cast<long>(m.rgb.size()) + delta));
    m.rgb_size = static_cast<int32_t>(m.rgb.size());
    damaged_then_good(m, good, reference, "RGB8 " + std::to_string(delta) + " bytes", false);
  }
  for (long delta : {-1L, 1L, -2L, 64L * 2, -64L * 48}) {
    rgbd_frame_t m = good;
    m.depth.resize(static_cast<size_t>(static_cast<long>(m.depth.size()) + delta));
    m.depth_size = static_cast<int32_t>(m.depth.size());
    damaged_then_good(m, good, reference, "depth " + std::to_string(delta) + " bytes", false);
  }
  rgbd_frame_t m = good;
  m.depth.pop_back();
  m.depth_size--;
  try {
    decode_rgbd(m, kChannel);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "CAMERA_RGBD: depth image has 6143 bytes, expected 6144");
  }
}

// The camera says one size, the payloads are of another (each encoding).
TEST(RgbdCodecDamage, PayloadsDisagreeingWithTheCameraSizeAreRejected) {
  for (const RgbdEncoding& encoding : {RgbdEncoding{}, compressed()}) {
    const rgbd_frame_t good = encode_rgbd(small_frame(), encoding);
    const RgbdFrame reference = decode_alone(good);
    for (const auto& [w, h] : std::vector<std::pair<int, int>>{{32, 48}, {64, 24}, {65, 48}, {64, 49}, {128, 96}}) {
      rgbd_frame_t m = good;
      m.camera.width = w;
      m.camera.height = h;
      m.camera.cx = 0.5 * (w - 1);
      m.camera.cy = 0.5 * (h - 1);
      damaged_then_good(m, good, reference,
                        std::to_string(w) + "x" + std::to_string(h) + " camera, encoding " +
                            std::to_string(encoding.rgb),
                        false);
      // The same with only one of the images, so that each image's own check is reached.
      rgbd_frame_t depth_only = m;
      depth_only.rgb_encoding = rgbd_frame_t::RGB_NONE;
      depth_only.rgb.clear();
      depth_only.rgb_size = 0;
      damaged_then_good(depth_only, good, reference, "depth only, " + std::to_string(w) + "x" + std::to_string(h),
                        false);
    }
  }
}

TEST(RgbdCodecDamage, ImpossibleCamerasAreRejectedAndPossibleOnesKept) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  using Damage = std::function<void(rgbd_frame_t&)>;
  const std::vector<std::pair<std::string, Damage>> impossible = {
      {"NaN fx", [&](rgbd_frame_t& m) { m.camera.fx = nan; }},
      {"infinite fy", [&](rgbd_frame_t& m) { m.camera.fy = inf; }},
      {"NaN cx", [&](rgbd_frame_t& m) { m.camera.cx = nan; }},
      {"-inf cy", [&](rgbd_frame_t& m) { m.camera.cy = -inf; }},
      {"zero fx", [](rgbd_frame_t& m) { m.camera.fx = 0.0; }},
      {"negative fy", [](rgbd_frame_t& m) { m.camera.fy = -60.0; }},
      {"fx 1e300", [](rgbd_frame_t& m) { m.camera.fx = 1e300; }},
      {"fy 1e-300", [](rgbd_frame_t& m) { m.camera.fy = 1e-300; }},
      {"fx for a 175 deg view", [](rgbd_frame_t& m) { m.camera.fx = 32.0 / std::tan(87.5 * kDegree); }},
      {"cx 1e12", [](rgbd_frame_t& m) { m.camera.cx = 1e12; }},
      {"cy two images up", [](rgbd_frame_t& m) { m.camera.cy = -96.0; }},
      {"zero width", [](rgbd_frame_t& m) { m.camera.width = 0; }},
      {"negative height", [](rgbd_frame_t& m) { m.camera.height = -48; }},
      {"width 100000", [](rgbd_frame_t& m) { m.camera.width = 100000; }},
      {"height INT32_MAX", [](rgbd_frame_t& m) { m.camera.height = std::numeric_limits<int32_t>::max(); }},
      {"NaN distortion",
       [&](rgbd_frame_t& m) {
         m.camera.distortion_model = kestrel::camera_info_t::DISTORTION_RADTAN;
         m.camera.distortion[0] = nan;
       }},
      {"distortion 1e200",
       [](rgbd_frame_t& m) {
         m.camera.distortion_model = kestrel::camera_info_t::DISTORTION_RADTAN;
         m.camera.distortion[4] = 1e200;
       }},
      {"unknown distortion model", [](rgbd_frame_t& m) { m.camera.distortion_model = 9; }},
      {"mounted 1e9 m away", [](rgbd_frame_t& m) { m.camera.T_body_camera.position[1] = 1e9; }},
      {"NaN mounting", [&](rgbd_frame_t& m) { m.camera.T_body_camera.position[2] = nan; }},
      {"zero quaternion", [](rgbd_frame_t& m) { for (double& q : m.camera.T_body_camera.orientation) q = 0.0; }},
  };
  for (const RgbdEncoding& encoding : {RgbdEncoding{}, compressed()}) {
    const rgbd_frame_t good = encode_rgbd(small_frame(), encoding);
    const RgbdFrame reference = decode_alone(good);
    for (const auto& [name, damage] : impossible) {
      rgbd_frame_t m = good;
      damage(m);
      damaged_then_good(m, good, reference, name, false);
    }
    // Unusual but real: a wide lens, a principal point off the image, strong distortion.
    rgbd_frame_t m = good;
    m.camera.fx = 5.0;  // 162 degrees across 64 px
    m.camera.cx = -10.0;
    m.camera.distortion_model = kestrel::camera_info_t::DISTORTION_RADTAN;
    m.camera.distortion[0] = -0.9;
    m.camera.distortion[4] = 12.0;
    const RgbdFrame g = decode_rgbd(m, kChannel);
    EXPECT_DOUBLE_EQ(g.camera.fx, 5.0);
    EXPECT_DOUBLE_EQ(g.camera.distortion[4], 12.0);
  }
  rgbd_frame_t m = encode_rgbd(small_frame());
  m.camera.fx = 1e300;
  try {
    decode_rgbd(m, kChannel);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "CAMERA_RGBD: implausible camera: fx = 1e+300 px for images 64 px wide "
                 "(a field of view outside 0.01..170 deg)");
  }
}

}  // namespace
}  // namespace kestrel::transport
