#pragma once
// Visibility: which surface each pixel sees, and at what inverse depth.
//
// Surfaces are planar, so for each one 1/z, and z times its texture coordinates, are affine
// in the pixel coordinates (u, v): a pixel's exact depth costs one multiply-add and one
// division, with no per-pixel ray-plane intersection. Polygons are clipped at the near plane
// and scan-converted with a depth test on 1/z; a pixel belongs to a polygon when its centre
// lies inside (left edges inclusive, right edges exclusive), so shared edges leave no cracks.

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "common/camera.h"
#include "drivers/sim/surface.h"

namespace kestrel::sim {

/// Per-view constants of one visible surface, in pixel coordinates of the camera.
struct ViewSurface {
  int surface = -1;                  ///< world surface id
  float inv_a = 0, inv_b = 0, inv_c = 0;  ///< 1/z = inv_a u + inv_b v + inv_c
  float s_a = 0, s_b = 0, s_c = 0, s_0 = 0;  ///< s (m) = z (s_a u + s_b v + s_c) + s_0
  float t_a = 0, t_b = 0, t_c = 0, t_0 = 0;
  float plane_d = 0;                 ///< n . X = plane_d for points X of the plane (camera frame)
};

class Rasterizer {
 public:
  static constexpr uint16_t kNone = 0xffff;

  Rasterizer(const PinholeCamera& camera, double near_m, double far_m);

  /// Draws every surface seen from T_world_camera (optical frame) into the buffers.
  void draw(const std::vector<Surface>& surfaces, const Eigen::Isometry3d& T_world_camera);

  const std::vector<ViewSurface>& visible() const { return visible_; }
  /// Index into visible() per pixel, kNone where nothing is seen.
  const uint16_t* ids(int v) const { return ids_.data() + static_cast<size_t>(v) * camera_.width; }
  /// 1/z per pixel (1/m), 0 where nothing is seen.
  const float* inverse_depth(int v) const { return inverse_depth_.data() + static_cast<size_t>(v) * camera_.width; }
  const PinholeCamera& camera() const { return camera_; }

 private:
  void scan(const std::vector<Eigen::Vector2d>& polygon, const ViewSurface& vs, uint16_t id);

  PinholeCamera camera_;
  double near_m_, far_m_;
  std::vector<ViewSurface> visible_;
  std::vector<uint16_t> ids_;
  std::vector<float> inverse_depth_;
};

}  // namespace kestrel::sim
