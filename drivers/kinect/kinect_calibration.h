#pragma once
// What it takes to turn a Kinect's raw depth into depth registered to its colour image: the
// IR (depth) camera's and the RGB camera's intrinsics, the rigid transform between them and
// the raw-to-metres model.
//
// Defaults (standard()): Nicolas Burrus's published calibration of a Kinect ("Kinect
// calibration", burrus.name, 2011), the values most Kinect software starts from:
//   RGB: fx 529.215, fy 525.564, cx 328.943, cy 267.481
//   IR:  fx 594.214, fy 591.041, cx 339.308, cy 242.739
//   R = [0.999846 0.001264 -0.017487; -0.001478 0.999924 -0.012251; 0.017470 0.012275 0.999772]
//   T = [0.019985, -0.000744, -0.010917] m
// Burrus's R, T are an OpenCV stereo calibration with the RGB camera first, so they map
// RGB-camera points into the IR camera: p_ir = R p_rgb + T, i.e. T_ir_rgb. (Consistent with the
// hardware: the RGB camera's centre then lies 2 cm along the IR camera's +x, the side it is
// mounted on.) Lens distortion is not modelled (Burrus's coefficients are small; the error is
// below a pixel over most of the image).
//
// Invariant after validate(): both cameras valid, T_ir_rgb a proper rigid transform,
// disparity model valid.

#include <Eigen/Geometry>

#include "common/camera.h"
#include "drivers/kinect/disparity_model.h"

namespace kestrel::kinect {

struct KinectCalibration {
  PinholeCamera rgb;
  PinholeCamera ir;
  Eigen::Isometry3d T_ir_rgb = Eigen::Isometry3d::Identity();  ///< RGB-camera points -> IR camera
  DisparityModel disparity;

  /// Burrus's calibration (above), 640x480 both.
  static KinectCalibration standard();
  /// IR camera = `camera`, no offset between the cameras: registration changes nothing but
  /// units. For depth that is registered already, and for tests.
  static KinectCalibration identity(const PinholeCamera& camera);

  Eigen::Isometry3d T_rgb_ir() const { return T_ir_rgb.inverse(); }
  /// Throws std::invalid_argument naming the bad part.
  void validate() const;
};

/// R and t as an Isometry3d; throws std::invalid_argument unless R is a rotation (orthonormal
/// to 1e-6, determinant +1) and everything is finite. R is re-orthonormalised.
Eigen::Isometry3d make_rigid(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

}  // namespace kestrel::kinect
