#include <gtest/gtest.h>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "kestrel/imu_t.hpp"
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
