#pragma once
// The planar pieces a world is made of.
//
// A Surface is a rectangle seen from one side: origin + s * axis_s + t * axis_t for s in
// [0, width], t in [0, height], with normal = axis_s x axis_t pointing to the side it is seen
// from (so s runs to the right and t upwards for a viewer facing it). Texture coordinates are
// (s, t) in metres, which makes a point's appearance independent of the view.
// A Box is a solid oriented box (furniture, thick walls); its six faces are Surfaces.

#include <Eigen/Geometry>
#include <array>

namespace kestrel::sim {

enum class SurfaceKind { kWall, kFloor, kCeiling, kBoxFace, kPanel };

const char* to_string(SurfaceKind kind);

struct Surface {
  int id = -1;  ///< index in World::surfaces()
  SurfaceKind kind = SurfaceKind::kWall;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< world point at (s, t) = (0, 0)
  Eigen::Vector3d axis_s = Eigen::Vector3d::UnitX();
  Eigen::Vector3d axis_t = Eigen::Vector3d::UnitY();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< axis_s x axis_t
  double width = 0.0;   ///< extent along axis_s, metres
  double height = 0.0;  ///< extent along axis_t, metres
  int material = 0;     ///< index in World::materials()
  double texture = 1.0; ///< texture density: 0 = blank, 1 = the material's full detail
  int box = -1;         ///< the Box this is a face of, or -1

  Eigen::Vector3d point(double s, double t) const { return origin + s * axis_s + t * axis_t; }
  std::array<Eigen::Vector3d, 4> corners() const {
    return {point(0, 0), point(width, 0), point(width, height), point(0, height)};
  }
  double area() const { return width * height; }
  bool is_vertical() const { return std::abs(normal.z()) < 1e-9; }
  /// Signed distance of p from the surface's plane (positive on the side it is seen from).
  double plane_distance(const Eigen::Vector3d& p) const { return normal.dot(p - origin); }
};

/// A solid box: points q with |(T_world_box^-1 q)_i| <= half_extent_i.
struct Box {
  Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();
  std::array<int, 6> faces{{-1, -1, -1, -1, -1, -1}};  ///< surfaces +x, -x, +y, -y, +z, -z
};

/// The rectangle (s, t) -> origin + s a + t b with a, b orthonormal, for a quad seen from the
/// side of a x b. Returns the Surface geometry with kind and material left to the caller.
Surface make_rectangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b, double width, double height);

}  // namespace kestrel::sim
