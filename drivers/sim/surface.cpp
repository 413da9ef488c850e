#include "drivers/sim/surface.h"

namespace kestrel::sim {

const char* to_string(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::kWall: return "wall";
    case SurfaceKind::kFloor: return "floor";
    case SurfaceKind::kCeiling: return "ceiling";
    case SurfaceKind::kBoxFace: return "box face";
    case SurfaceKind::kPanel: return "panel";
  }
  return "?";
}

Surface make_rectangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       double width, double height) {
  Surface s;
  s.origin = origin;
  s.axis_s = a.normalized();
  s.axis_t = b.normalized();
  s.normal = s.axis_s.cross(s.axis_t).normalized();
  s.width = width;
  s.height = height;
  return s;
}

}  // namespace kestrel::sim
