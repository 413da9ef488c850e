#include <gtest/gtest.h>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/pose_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::transport {
namespace {

kestrel::imu_t sample_imu() {
  kestrel::imu_t m{};
  m.utime = 123;
  m.seq = 7;
  m.fields = kestrel::imu_t::HAS_GYRO | kestrel::imu_t::HAS_ACCEL;
  m.linear_acceleration[2] = 9.81;
  return m;
}

TEST(Message, RoundTrip) {
  const auto bytes = encode_message(sample_imu());
  const auto m = decode_message<kestrel::imu_t>(bytes.data(), bytes.size(), "IMU");
  EXPECT_EQ(m.utime, 123);
  EXPECT_EQ(m.seq, 7);
  EXPECT_DOUBLE_EQ(m.linear_acceleration[2], 9.81);
  EXPECT_EQ(message_utime(m), 123);
}

TEST(Message, WrongTypeNamesTheChannel) {
  const auto bytes = encode_message(sample_imu());
  try {
    decode_message<kestrel::vo_update_t>(bytes.data(), bytes.size(), "VO_UPDATE");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("VO_UPDATE: ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("vo_update_t"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("another fingerprint"), std::string::npos) << e.what();
  }
}

// Each failure says which it is: too short to hold a fingerprint, a truncated message of the
// right type, extra bytes after one.
TEST(Message, TruncatedAndOverlongAreRejected) {
  auto bytes = encode_message(sample_imu());
  auto error = [](const std::vector<uint8_t>& b, size_t n) {
    try {
      decode_message<kestrel::imu_t>(b.data(), n, "IMU");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error(bytes, bytes.size() - 1).find("truncated or corrupt imu_t message"), std::string::npos)
      << error(bytes, bytes.size() - 1);
  EXPECT_NE(error(bytes, 0).find("too short"), std::string::npos) << error(bytes, 0);
  bytes.push_back(0);
  EXPECT_THROW(decode_message<kestrel::imu_t>(bytes.data(), bytes.size(), "IMU"), InputError);
}

// An array count the message cannot hold (negative, or more elements than bytes left) is a
// corrupt message, refused before anything is sized from it: lcm-gen's decoders resized first
// (std::length_error escaped for -1; 2^31 - 1 zeroed 2 GB), cmake/lcm_guard_counts.cmake.
TEST(Message, ArrayCountsBeyondTheMessageAreCorruptNotAllocated) {
  // The count's offset in the encoded message: where its bytes differ between two counts.
  const auto count_at = [](const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
    size_t i = 0;
    while (i < a.size() && a[i] == b[i]) ++i;
    return i - 3;  // a big-endian int32 whose last byte differs
  };
  const auto set_count = [](std::vector<uint8_t> bytes, size_t at, int32_t n) {
    const auto u = static_cast<uint32_t>(n);
    for (int k = 0; k < 4; ++k) bytes[at + static_cast<size_t>(k)] = static_cast<uint8_t>(u >> (24 - 8 * k));
    return bytes;
  };
  kestrel::rgbd_frame_t frame{};
  frame.rgb_encoding = kestrel::rgbd_frame_t::RGB_NONE;
  frame.depth_encoding = kestrel::rgbd_frame_t::DEPTH_U16_MM;
  frame.depth_size = 2;
  frame.depth = {1, 2};
  kestrel::rgbd_frame_t three = frame;
  three.depth_size = 3;
  three.depth = {1, 2, 3};
  const auto good = encode_message(frame);
  const size_t at = count_at(good, encode_message(three));
  for (const int32_t n : {-1, -2147483647 - 1, 3, 1 << 20, 2147483647}) {
    const auto bad = set_count(good, at, n);
    try {
      decode_message<kestrel::rgbd_frame_t>(bad.data(), bad.size(), "CAMERA_RGBD");
      ADD_FAILURE() << "count " << n << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("truncated or corrupt rgbd_frame_t"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(decode_message<kestrel::rgbd_frame_t>(good.data(), good.size(), "CAMERA_RGBD").depth, frame.depth);

  // Nested counts too: a state's covariance is cov_dim x cov_dim.
  kestrel::state_t s{};
  s.cov_dim = 2;
  s.covariance = {{1, 0}, {0, 1}};
  kestrel::state_t s3 = s;
  s3.cov_dim = 3;
  s3.covariance = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const auto good_state = encode_message(s);
  const size_t dim_at = count_at(good_state, encode_message(s3));
  for (const int32_t n : {-1, 46341, 2147483647}) {
    const auto bad = set_count(good_state, dim_at, n);
    EXPECT_THROW(decode_message<kestrel::state_t>(bad.data(), bad.size(), "STATE"), InputError) << n;
  }
}

// A string's length counts its NUL: 0 or less is a corrupt message (assign(p, -1) threw
// std::length_error out of lcm-gen's decoder).
TEST(Message, StringLengthsBelowOneAreCorrupt) {
  kestrel::pose_t p{};
  p.parent_frame = "w";
  p.child_frame = "b";
  const auto good = encode_message(p);
  constexpr size_t kParentLength = 8 + 8;  // after the fingerprint and utime
  ASSERT_EQ(good[kParentLength + 3], 2);   // "w" and its NUL
  for (const uint8_t fill : {0x00, 0xff}) {
    auto bad = good;
    for (size_t k = 0; k < 4; ++k) bad[kParentLength + k] = fill;
    EXPECT_THROW(decode_message<kestrel::pose_t>(bad.data(), bad.size(), "POSE"), InputError) << int(fill);
  }
  EXPECT_EQ(decode_message<kestrel::pose_t>(good.data(), good.size(), "POSE").parent_frame, "w");
}

TEST(Convert, PoseRoundTripAndValidation) {
  const Eigen::Isometry3d T = se3::make(Eigen::Quaterniond(0.5, 0.5, -0.5, 0.5), Eigen::Vector3d(1, 2, 3));
  const auto m = to_message(T);
  EXPECT_DOUBLE_EQ(m.orientation[0], 0.5);  // w first
  EXPECT_TRUE(from_message(m, "pose").isApprox(T));
  auto bad = m;
  bad.position[1] = std::nan("");
  EXPECT_THROW(from_message(bad, "pose"), InputError);
  bad = m;
  bad.orientation[0] = 3.0;
  EXPECT_THROW(from_message(bad, "pose"), InputError);
}

TEST(Convert, CovarianceIsRowMajor) {
  Matrix6d c = Matrix6d::Zero();
  c(0, 1) = 5.0;
  double a[36];
  covariance_to(c, a);
  EXPECT_DOUBLE_EQ(a[1], 5.0);
  EXPECT_TRUE(covariance_from(a).isApprox(c));
}

}  // namespace
}  // namespace kestrel::transport
