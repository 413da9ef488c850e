// Raw 11-bit Kinect depth <-> metres (drivers/kinect/disparity_model.h), and the
// accelerometer's counts and axes.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drivers/kinect/accelerometer.h"
#include "drivers/kinect/disparity_model.h"

namespace kestrel::kinect {
namespace {

TEST(DisparityModel, KnownValues) {
  const DisparityModel m;
  EXPECT_NEAR(m.metres(0), 1.0 / 3.3309495161, 1e-12);  // 0.300 m, the nearest raw value
  // raw 600: 1 / (3.3309495161 - 1.84266096) = 0.6719 m
  EXPECT_NEAR(m.metres(600), 1.0 / (3.3309495161 - 600 * 0.0030711016), 1e-12);
  EXPECT_NEAR(m.metres(600), 0.67190, 1e-4);
  EXPECT_EQ(m.metres(DisparityModel::kNoReading), 0.0);
  EXPECT_EQ(m.metres(1085), 0.0);  // beyond -b/a = 1084.6: no finite depth
  EXPECT_GT(m.metres(1084), 500.0);
  EXPECT_NEAR(m.step_at(1.0), 0.0030711016, 1e-12);
}

TEST(DisparityModel, DepthGrowsWithTheRawValue) {
  const DisparityModel m;
  for (uint16_t raw = 1; raw <= 1084; ++raw) ASSERT_GT(m.metres(raw), m.metres(raw - 1)) << raw;
}

// metres -> raw -> metres at the ranges the Kinect is used at: within half a raw step (the
// quantisation) of the input, and the step itself as the model predicts.
TEST(DisparityModel, RoundTripIsWithinHalfAQuantisationStep) {
  const DisparityModel m;
  for (double z : {0.5, 1.0, 2.0, 3.0, 4.0}) {
    const uint16_t raw = m.raw(z);
    ASSERT_LT(raw, DisparityModel::kNoReading) << z;
    const double back = m.metres(raw);
    const double step = m.metres(static_cast<uint16_t>(raw + 1)) - back;
    EXPECT_LE(std::abs(back - z), 0.5 * step * 1.01) << z;
    EXPECT_NEAR(step, m.step_at(z), 0.05 * m.step_at(z)) << z;
  }
  // The published figures: 0.8 mm at 0.5 m ... 49 mm at 4 m per raw step.
  EXPECT_NEAR(m.step_at(0.5), 0.00077, 0.00001);
  EXPECT_NEAR(m.step_at(4.0), 0.0491, 0.0001);
  // Every raw value survives raw -> metres -> raw exactly.
  for (uint16_t raw = 0; raw <= 1084; ++raw) ASSERT_EQ(m.raw(m.metres(raw)), raw);
}

TEST(DisparityModel, UnrepresentableDepthsHaveNoReading) {
  const DisparityModel m;
  for (double z : {0.0, -1.0, 0.2, std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity(), 1e6}) {
    EXPECT_EQ(m.raw(z), DisparityModel::kNoReading) << z;
  }
  EXPECT_EQ(m.raw(0.3002), 0);  // 1/b, raw 0
  EXPECT_EQ(m.raw(0.300), 0);   // raw 0's depth rounded to millimetres still maps back
  EXPECT_EQ(m.raw(0.299), DisparityModel::kNoReading);  // more than a step nearer
}

TEST(DisparityModel, TableAndValidation) {
  const DisparityModel m;
  const auto t = m.table();
  for (uint16_t raw : {0, 1, 600, 1084, 1085, 2047}) EXPECT_EQ(t[raw], static_cast<float>(m.metres(raw)));
  EXPECT_NO_THROW(m.validate());
  DisparityModel bad;
  bad.a = 0.001;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad.a = -0.003;
  bad.b = std::nan("");
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

TEST(Accelerometer, CountsAndAxes) {
  EXPECT_EQ(mps2_to_counts(kStandardGravity), 819);
  EXPECT_EQ(mps2_to_counts(-kStandardGravity / 819.0 * 57.0), -57);
  EXPECT_EQ(mps2_to_counts(1e9), 32767);  // saturates
  EXPECT_EQ(mps2_to_counts(std::nan("")), 0);
  for (int16_t c : {-819, -57, 0, 1, 468, 653}) EXPECT_EQ(mps2_to_counts(counts_to_mps2(c)), c);
  // TUM's recorded values are whole counts: 0.682514 m/s^2 = 57 counts.
  EXPECT_EQ(mps2_to_counts(0.682514), 57);
  EXPECT_NEAR(counts_to_mps2(57), 0.682514, 1e-6);
  const Eigen::Vector3d a = accel_to_camera({1.0, 2.0, 3.0});
  EXPECT_EQ(a, Eigen::Vector3d(-1.0, -2.0, 3.0));
}

}  // namespace
}  // namespace kestrel::kinect
