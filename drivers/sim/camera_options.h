#pragma once
// Options of the simulated Kinect: intrinsics and mounting, the depth sensor model and the
// colour sensor model. Every field has its default and unit; kestrel-sim exposes them.

#include <Eigen/Geometry>

#include "common/camera.h"

namespace kestrel::sim {

/// The Kinect's depth: disparity from a structured-light pair, registered to the RGB camera.
struct DepthOptions {
  bool noise = true;             ///< random noise and random dropouts (off: exact depth, quantised)
  double min_range_m = 0.5;      ///< closer readings are missing
  double max_range_m = 4.0;      ///< farther readings are missing
  double noise_k = 1.4e-3;       ///< sigma_z = noise_k * z^2, 1/m (Khoshelham & Elberink 2012)
  double ir_focal_px = 580.0;    ///< IR camera focal length, pixels
  double baseline_m = 0.075;     ///< IR camera to projector
  int subpixel = 8;              ///< disparity resolution: 1/subpixel pixel (quantisation step)
  double projector_offset_m = 0.075;  ///< projector to the right (+x) of the camera: shadows
  double edge_jump = 0.03;       ///< a relative depth jump larger than this is a discontinuity
  double edge_dropout = 0.5;     ///< probability of losing the far pixel at a discontinuity
  /// IR return rho * cos(incidence) / z^2 (rho = albedo, z in m): below `return_low` the
  /// reading is missing, above `return_high` present, linear odds in between. This makes
  /// dark, far and grazing surfaces lose depth.
  double return_low = 0.010;
  double return_high = 0.030;
};

/// The colour sensor: exposure, optics, noise.
struct RgbOptions {
  bool noise = true;             ///< photon and read noise
  double exposure = 1.0;         ///< digital numbers = 255 * exposure * albedo * irradiance
  /// Auto-exposure (rgb_sensor.h): the exposure is lowered where the frame's mean grey would be
  /// above this (the brightest of a Kinect's frames in TUM's freiburg1: 155 / 161); 0 = off.
  double max_mean_grey = 160.0;
  double read_noise_dn = 1.5;    ///< sigma of the signal-independent noise, digital numbers
  double shot_noise_dn = 0.08;   ///< variance of the photon noise per digital number of signal
  double vignetting = 0.25;      ///< relative fall-off of brightness at the image corners
  bool optics_blur = true;       ///< 3x3 binomial point-spread (lens and demosaicing softness)
  int motion_blur_samples = 1;   ///< renders averaged over the exposure (1 = no motion blur)
  double exposure_time_s = 0.02; ///< exposure over which motion blur is integrated
};

struct CameraOptions {
  PinholeCamera camera;  ///< 640 x 480, fx = fy = 525, cx = 319.5, cy = 239.5 (Kinect)
  Eigen::Isometry3d T_body_camera = default_T_body_camera();
  double rate_hz = 30.0;
  double near_m = 0.05;  ///< geometry closer than this is clipped
  double far_m = 60.0;   ///< surfaces entirely farther than this are not drawn
  DepthOptions depth;
  RgbOptions rgb;

  /// Optical frame (x right, y down, z forward) `forward_m` ahead of the body origin, looking
  /// along body x and pitched down by `tilt_deg` (as on the paper's vehicle).
  static Eigen::Isometry3d default_T_body_camera(double tilt_deg = 10.0, double forward_m = 0.1,
                                                 double down_m = 0.05) {
    Eigen::Matrix3d R_body_optical;
    R_body_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // columns: optical x, y, z in body axes
    const double tilt = tilt_deg * 3.14159265358979323846 / 180.0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitY()).toRotationMatrix() * R_body_optical;
    T.translation() = Eigen::Vector3d(forward_m, 0.0, -down_m);
    return T;
  }
};

}  // namespace kestrel::sim
