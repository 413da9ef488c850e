#pragma once
// The KinectCalibration as command-line / --config options, shared by kestrel-kinect and
// kestrel-tum-to-fakenect so that both sides of a fakenect round trip use the same values.
//
//   --rgb-intrinsics fx,fy,cx,cy          RGB camera (default: Burrus)
//   --ir-intrinsics fx,fy,cx,cy           IR (depth) camera (default: Burrus)
//   --rgb-in-ir-rotation r11,...,r33      R of T_ir_rgb, row-major (default: Burrus)
//   --rgb-in-ir-translation tx,ty,tz      t of T_ir_rgb, metres (default: Burrus)
//   --disparity a,b                       z = 1 / (a raw + b) (default: Burrus)
//   --identity-calibration                IR camera = RGB camera, no offset (pre-registered)

#include <CLI/CLI.hpp>
#include <vector>

#include "drivers/kinect/kinect_calibration.h"

namespace kestrel::kinect {

struct CalibrationOptions {
  std::vector<double> rgb_intrinsics;
  std::vector<double> ir_intrinsics;
  std::vector<double> rotation;
  std::vector<double> translation;
  std::vector<double> disparity;
  bool identity = false;

  /// Fills the defaults from KinectCalibration::standard() and declares the options.
  void add_to(CLI::App& app);
  /// The calibration the options describe; throws CLI::ValidationError naming the option.
  KinectCalibration calibration() const;
};

}  // namespace kestrel::kinect
