#pragma once
// The Kinect's raw 11-bit depth values (FREENECT_DEPTH_11BIT) and metres.
//
// The Kinect measures the shift (disparity) of its projected speckle pattern; depth is
// inversely proportional to disparity, and the raw value is an affine function of disparity.
// So 1/z is affine in the raw value:
//
//     z = 1 / (a * raw + b)        raw = (1/z - b) / a
//
// with Nicolas Burrus's published least-squares fit over many Kinects, a = -0.0030711016 m^-1
// and b = 3.3309495161 m^-1 ("Kinect calibration", burrus.name, 2011; the same model as
// ROS's baseline/offset form z = 8 B f / (d_off - raw)). Raw 2047 means "no reading"
// (FREENECT_DEPTH_RAW_NO_VALUE). Raw 0 is z = 1/b = 0.300 m; z grows without bound as raw
// approaches -b/a = 1084.6, so raw values from 1085 to 2046 have no depth.
//
// Quantisation: one raw step changes z by |a| z^2 (first order): 0.8 mm at 0.5 m, 3.1 mm at
// 1 m, 12 mm at 2 m, 28 mm at 3 m, 49 mm at 4 m. Rounding to the nearest raw value makes the
// round trip metres -> raw -> metres exact to within half of that.

#include <array>
#include <cstdint>

namespace kestrel::kinect {

struct DisparityModel {
  static constexpr uint16_t kNoReading = 2047;

  double a = -0.0030711016;  ///< m^-1 per raw unit (negative)
  double b = 3.3309495161;   ///< m^-1

  /// z in metres for a raw value, or 0 for "no reading" and values outside the model.
  double metres(uint16_t raw) const;
  /// The model's raw value for z rounded to the nearest integer (up to one step nearer than
  /// raw 0 gives 0), or kNoReading when z is not finite and positive or lies outside what
  /// raw values 0..2046 can express.
  uint16_t raw(double z_m) const;
  /// First-order change of z for one raw step at depth z, metres.
  double step_at(double z_m) const;
  /// Throws std::invalid_argument unless a < 0 < b and both are finite.
  void validate() const;
  /// metres(raw) for every raw value, as float (the driver's per-pixel lookup).
  std::array<float, 2048> table() const;
};

}  // namespace kestrel::kinect
