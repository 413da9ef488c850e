#pragma once
// Kinect raw depth (IR camera, 11-bit) <-> depth registered to the RGB camera (millimetres),
// with one KinectCalibration.
//
//   register_raw:  raw -> metres (DisparityModel) -> warp IR -> RGB (z-buffered) -> mm
//   unregister_mm: mm -> metres -> warp RGB -> IR (z-buffered) -> raw
//
// unregister_mm is what a recording of the scene in the RGB camera would have looked like to
// the IR camera; register_raw of it gives the input back where both warps keep the pixel,
// within the raw quantisation (disparity_model.h) and up to resampling to the nearest pixel.
// With KinectCalibration::identity() both directions change nothing but units, so the round
// trip is exact within the quantisation at every pixel.

#include <array>

#include <opencv2/core/mat.hpp>

#include "drivers/kinect/depth_warp.h"
#include "drivers/kinect/kinect_calibration.h"

namespace kestrel::kinect {

class DepthRegistration {
 public:
  /// Throws std::invalid_argument for an invalid calibration.
  explicit DepthRegistration(const KinectCalibration& calibration);

  /// raw_ir: CV_16UC1 raw values, ir.width x ir.height (>= 2047 = no reading). Returns
  /// CV_16UC1 millimetres registered to the RGB camera, rgb.width x rgb.height, 0 = none.
  cv::Mat register_raw(const cv::Mat& raw_ir) const;

  /// depth_rgb_mm: CV_16UC1 millimetres, rgb.width x rgb.height, 0 = none. Returns CV_16UC1
  /// raw values in the IR camera, 2047 where there is no reading.
  cv::Mat unregister_mm(const cv::Mat& depth_rgb_mm) const;

  const KinectCalibration& calibration() const { return calibration_; }

 private:
  KinectCalibration calibration_;
  std::array<float, 2048> metres_of_raw_;
  DepthWarp ir_to_rgb_;
  DepthWarp rgb_to_ir_;
};

}  // namespace kestrel::kinect
