#pragma once
// The map from raw (distorted) pixel coordinates to ideal pinhole coordinates of the same
// camera, so that rays and reprojection errors are exact under the lens model the source
// reports. Depth images registered to the colour image share its raw pixel grid, which is why
// depth is looked up at raw pixels while rays come from ideal ones.
//
// Invariant: after reset(camera), ideal(u, v) is within 0.01 px of the exact inverse of the
// Brown-Conrady model with camera.distortion over the image (bilinear between nodes of the
// exact inverse every 4 px; on freiburg1's lens: median 3e-4, 99 % within 5e-3 px, a tenth of
// a percent of the features' pixel noise); with zero distortion it is the identity.

#include <Eigen/Core>
#include <vector>

#include "common/camera.h"

namespace kestrel::sensors {

class Lens {
 public:
  /// Prepares the map for `camera` (a table of the inverse distortion when `use_distortion`
  /// and the camera reports any; nothing otherwise).
  void reset(const PinholeCamera& camera, bool use_distortion);

  /// True if reset() was called for this camera and setting.
  bool prepared_for(const PinholeCamera& camera, bool use_distortion) const;

  /// Ideal pinhole pixel coordinates of the raw level-0 pixel (u, v), bilinear in the table.
  Eigen::Vector2f ideal(float u, float v) const;

  /// Unit-depth ray (x/z, y/z, 1) through the raw level-0 pixel (u, v).
  Eigen::Vector3f ray(float u, float v) const;

  const PinholeCamera& camera() const { return camera_; }
  bool distorted() const { return !table_.empty(); }
  bool uses_distortion() const { return use_distortion_; }  ///< the setting reset() was given

 private:
  PinholeCamera camera_;
  bool use_distortion_ = false;
  bool prepared_ = false;
  // Ideal coordinates of every kStep-th raw pixel in both directions (one node past the last
  // pixel), row-major, cols_ x rows_ nodes: 150 kB for VGA, so that the features' lookups
  // stay in cache (a table of every pixel, 2.4 MB, missed it on most of them).
  static constexpr int kStep = 4;
  int cols_ = 0, rows_ = 0;
  std::vector<Eigen::Vector2f> table_;
};

}  // namespace kestrel::sensors
