// The Kinect calibration as command-line options (calibration_options.h).

#include <gtest/gtest.h>

#include <algorithm>

#include "drivers/kinect/calibration_options.h"

namespace kestrel::kinect {
namespace {

KinectCalibration parse(std::vector<std::string> args) {
  CLI::App app;
  CalibrationOptions o;
  o.add_to(app);
  std::reverse(args.begin(), args.end());  // CLI11 takes a reversed vector
  app.parse(args);
  return o.calibration();
}

TEST(CalibrationOptions, DefaultsAreTheStandardCalibration) {
  const KinectCalibration c = parse({});
  const KinectCalibration s = KinectCalibration::standard();
  EXPECT_EQ(c.rgb.fx, s.rgb.fx);
  EXPECT_EQ(c.ir.cy, s.ir.cy);
  EXPECT_TRUE(c.T_ir_rgb.isApprox(s.T_ir_rgb, 1e-12));
  EXPECT_EQ(c.disparity.a, s.disparity.a);
}

TEST(CalibrationOptions, OverridesAndIdentity) {
  const KinectCalibration c =
      parse({"--rgb-intrinsics", "517.3,516.5,318.6,255.3", "--rgb-in-ir-translation", "0.025,0,0",
             "--rgb-in-ir-rotation", "1,0,0,0,1,0,0,0,1", "--disparity", "-0.003,3.3"});
  EXPECT_EQ(c.rgb.fx, 517.3);
  EXPECT_EQ(c.rgb.cy, 255.3);
  EXPECT_EQ(c.T_ir_rgb.translation().x(), 0.025);
  EXPECT_TRUE(c.T_ir_rgb.linear().isIdentity());
  EXPECT_EQ(c.disparity.b, 3.3);

  const KinectCalibration id = parse({"--identity-calibration", "--rgb-intrinsics", "500,501,320,240"});
  EXPECT_EQ(id.ir.fx, 500.0);
  EXPECT_EQ(id.ir.fy, 501.0);
  EXPECT_TRUE(id.T_ir_rgb.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(CalibrationOptions, BadValuesNameTheOption) {
  auto error_of = [](std::vector<std::string> args) -> std::string {
    try {
      parse(std::move(args));
    } catch (const CLI::Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of({"--rgb-intrinsics", "0,500,320,240"}).find("--rgb-intrinsics"), std::string::npos);
  EXPECT_NE(error_of({"--ir-intrinsics", "500,nan,320,240"}).find("--ir-intrinsics"), std::string::npos);
  EXPECT_NE(error_of({"--rgb-in-ir-rotation", "1,0,0,0,1,0,0,0,2"}).find("rotation"), std::string::npos);
  EXPECT_NE(error_of({"--disparity", "0.003,3.3"}).find("--disparity"), std::string::npos);
  EXPECT_FALSE(error_of({"--rgb-intrinsics", "500,500,320"}).empty());  // three values, not four
}

}  // namespace
}  // namespace kestrel::kinect
