#pragma once
// Renders Kinect-like RGB-D frames of a World.
//
// Geometry is exact (rasterizer.h); colour is the surfaces' procedural albedo, mip-mapped
// (trilinear) so distant textures do not alias, times their baked light maps; then the colour
// sensor (rgb_sensor.h) and the depth sensor (kinect_depth.h) models. Depth is registered to
// the RGB image, as the Kinect delivers it. Motion blur averages renders over the exposure.
//
// A Renderer keeps its working buffers: it is not thread-safe; use one per thread. The same
// seed, pose and frame number always give the same bytes.

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "common/rgbd_frame.h"
#include "drivers/sim/camera_options.h"
#include "drivers/sim/rasterizer.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {

class Renderer {
 public:
  /// `world` must outlive the renderer; `seed` keys the sensor noise.
  Renderer(const World& world, const CameraOptions& options, uint64_t seed);

  /// The frame seen from T_world_camera (optical frame); `seq` keys this frame's noise.
  RgbdFrame render(const Eigen::Isometry3d& T_world_camera, int64_t utime, int64_t seq);
  /// With motion blur: colour averaged over `exposure` (poses across the exposure, in time
  /// order); depth from the middle pose.
  RgbdFrame render(const std::vector<Eigen::Isometry3d>& exposure, int64_t utime, int64_t seq);

  /// Exact geometry of the (middle) pose of the last render: depth along the optical axis in
  /// metres (CV_32FC1, 0 = nothing seen) and the surface seen (CV_32SC1, -1 = none).
  cv::Mat ideal_depth() const;
  cv::Mat surface_ids() const;

  const CameraOptions& options() const { return options_; }
  const World& world() const { return world_; }

 private:
  // Adds the radiance seen from the rasterised view to the colour planes; with `ir`, also
  // fills the IR return (albedo * cos(incidence)) for the depth model. Without `accumulate`
  // the planes are overwritten (background 0) instead of added to.
  void shade(bool ir, bool accumulate);

  const World& world_;
  CameraOptions options_;
  uint64_t seed_;
  Rasterizer raster_;
  std::vector<float> planes_[3];
  std::vector<float> ir_return_;
  std::vector<float> ray_inverse_norm_;  // 1 / |(x, y, 1)| per pixel
};

}  // namespace kestrel::sim
