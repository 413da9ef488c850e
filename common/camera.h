#pragma once
// The pinhole model of an RGB-D camera whose depth is registered to its colour image.
//
// Invariant: (0, 0) is the centre of the top-left pixel; `distortion` is the lens model of the
// images as the source delivers them (zero when it undistorted them or its lens has none;
// TUM's freiburg1 reports its calibration with raw images). project()/backproject() are the
// pinhole model of ideal (undistorted) pixels and do not apply it: a consumer of raw pixels
// maps them to ideal ones first (sensors::Lens, which the VO and SLAM's keyframe features use), or
// reads each ideal pixel's value at its raw pixel, distort() (the mapper's decimated grid).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace kestrel {

struct PinholeCamera {
  int width = 640;
  int height = 480;
  double fx = 525.0;
  double fy = 525.0;
  double cx = 319.5;
  double cy = 239.5;
  std::array<double, 5> distortion{};  ///< k1, k2, p1, p2, k3 (OpenCV order)

  /// A 640 x 480 camera (Kinect-class sensors, TUM sequences) without distortion.
  static PinholeCamera vga(double fx_, double fy_, double cx_, double cy_) {
    PinholeCamera c;
    c.fx = fx_;
    c.fy = fy_;
    c.cx = cx_;
    c.cy = cy_;
    return c;
  }

  /// Point in the camera optical frame seen at pixel (u, v) with depth z (metres, along +z).
  Eigen::Vector3d backproject(double u, double v, double z) const {
    return {(u - cx) * z / fx, (v - cy) * z / fy, z};
  }
  /// Pixel of a point in the optical frame; the point must have z > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  /// True if the images carry lens distortion (any coefficient non-zero).
  bool distorted() const;
  /// Raw (distorted) pixel of the ideal pinhole pixel (u, v) under `distortion` (OpenCV's
  /// Brown-Conrady model, k1 k2 p1 p2 k3); (u, v) itself without distortion.
  Eigen::Vector2d distort(double u, double v) const;
  /// The same model on normalised coordinates (x / z, y / z): the distorted normalised point,
  /// and d(distorted) / d(x, y) in `jacobian` when one is given (for inverting the model).
  Eigen::Vector2d distort_normalized(double x, double y, Eigen::Matrix2d* jacobian = nullptr) const;
  /// True if (u, v) lies inside the image, `border` pixels away from its edges.
  bool contains(double u, double v, double border = 0.0) const {
    return u >= border - 0.5 && v >= border - 0.5 && u <= width - 0.5 - border &&
           v <= height - 0.5 - border;
  }
  /// This camera for an image scaled by `s` (e.g. 0.5 for the next pyramid level).
  PinholeCamera scaled(double s) const;
  /// Throws InputError naming `what` unless the values are usable.
  void validate(const char* what) const;
};

/// Beyond PinholeCamera::validate: throws InputError naming `what` for values no pinhole camera
/// has (a field of view beyond 0.01..170 degrees, a principal point more than an image away from
/// the image, a lens coefficient beyond +-1000, a camera mounted more than 100 m from the body).
/// Every reader of a camera from outside (a frame on the wire, a TUM folder's camera.txt) checks
/// it, so the consumers' back-projection never turns such values into garbage points.
void check_plausible_camera(const PinholeCamera& camera, const Eigen::Isometry3d& T_body_camera, const char* what);

}  // namespace kestrel
