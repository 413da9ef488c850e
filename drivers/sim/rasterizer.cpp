#include "drivers/sim/rasterizer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kestrel::sim {
namespace {

// Sutherland-Hodgman clipping of a polygon (camera frame) to z >= near.
std::vector<Eigen::Vector3d> clip_near(const std::vector<Eigen::Vector3d>& in, double near) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(in.size() + 2);
  for (size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3d& a = in[i];
    const Eigen::Vector3d& b = in[(i + 1) % in.size()];
    const bool a_in = a.z() >= near, b_in = b.z() >= near;
    if (a_in) out.push_back(a);
    if (a_in != b_in) {
      // Interpolate from the inside end so both polygons sharing an edge get the same point.
      const Eigen::Vector3d& p = a_in ? a : b;
      const Eigen::Vector3d& q = a_in ? b : a;
      out.push_back(p + (q - p) * ((p.z() - near) / (p.z() - q.z())));
    }
  }
  return out;
}

}  // namespace

Rasterizer::Rasterizer(const PinholeCamera& camera, double near_m, double far_m)
    : camera_(camera), near_m_(near_m), far_m_(far_m) {
  const size_t n = static_cast<size_t>(camera.width) * camera.height;
  ids_.assign(n, kNone);
  inverse_depth_.assign(n, 0.0f);
}

void Rasterizer::draw(const std::vector<Surface>& surfaces, const Eigen::Isometry3d& T_world_camera) {
  std::fill(ids_.begin(), ids_.end(), kNone);
  std::fill(inverse_depth_.begin(), inverse_depth_.end(), 0.0f);
  visible_.clear();
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  const Eigen::Matrix3d R = T_camera_world.linear();
  const Eigen::Vector3d p = T_camera_world.translation();
  const double fx = camera_.fx, fy = camera_.fy, cx = camera_.cx, cy = camera_.cy;
  std::vector<Eigen::Vector3d> corners(4);
  std::vector<Eigen::Vector2d> projected;
  for (const Surface& s : surfaces) {
    const Eigen::Vector3d n = R * s.normal;
    const Eigen::Vector3d o = R * s.origin + p;
    const double d = n.dot(o);
    if (d >= 0.0) continue;  // seen from behind (or edge-on)
    const auto world_corners = s.corners();
    bool all_far = true, all_near = true;
    for (int i = 0; i < 4; ++i) {
      corners[static_cast<size_t>(i)] = R * world_corners[static_cast<size_t>(i)] + p;
      all_far = all_far && corners[static_cast<size_t>(i)].z() > far_m_;
      all_near = all_near && corners[static_cast<size_t>(i)].z() < near_m_;
    }
    if (all_far || all_near) continue;
    const std::vector<Eigen::Vector3d> clipped = clip_near(corners, near_m_);
    if (clipped.size() < 3) continue;
    projected.clear();
    double umin = 1e300, umax = -1e300, vmin = 1e300, vmax = -1e300;
    for (const Eigen::Vector3d& c : clipped) {
      projected.emplace_back(fx * c.x() / c.z() + cx, fy * c.y() / c.z() + cy);
      umin = std::min(umin, projected.back().x()), umax = std::max(umax, projected.back().x());
      vmin = std::min(vmin, projected.back().y()), vmax = std::max(vmax, projected.back().y());
    }
    if (umax < -0.5 || vmax < -0.5 || umin > camera_.width - 0.5 || vmin > camera_.height - 0.5) continue;
    if (visible_.size() >= kNone) break;

    ViewSurface vs;
    vs.surface = s.id;
    vs.plane_d = static_cast<float>(d);
    vs.inv_a = static_cast<float>(n.x() / (fx * d));
    vs.inv_b = static_cast<float>(n.y() / (fy * d));
    vs.inv_c = static_cast<float>((n.z() - n.x() * cx / fx - n.y() * cy / fy) / d);
    const Eigen::Vector3d es = R * s.axis_s, et = R * s.axis_t;
    vs.s_a = static_cast<float>(es.x() / fx);
    vs.s_b = static_cast<float>(es.y() / fy);
    vs.s_c = static_cast<float>(es.z() - es.x() * cx / fx - es.y() * cy / fy);
    vs.s_0 = static_cast<float>(-es.dot(o));
    vs.t_a = static_cast<float>(et.x() / fx);
    vs.t_b = static_cast<float>(et.y() / fy);
    vs.t_c = static_cast<float>(et.z() - et.x() * cx / fx - et.y() * cy / fy);
    vs.t_0 = static_cast<float>(-et.dot(o));
    const auto id = static_cast<uint16_t>(visible_.size());
    visible_.push_back(vs);
    scan(projected, vs, id);
  }
}

void Rasterizer::scan(const std::vector<Eigen::Vector2d>& poly, const ViewSurface& vs, uint16_t id) {
  double vmin = 1e300, vmax = -1e300;
  for (const auto& q : poly) vmin = std::min(vmin, q.y()), vmax = std::max(vmax, q.y());
  const int v0 = std::max(0, static_cast<int>(std::ceil(vmin)));
  const int v1 = std::min(camera_.height - 1, static_cast<int>(std::ceil(vmax)) - 1);
  const int w = camera_.width;
  for (int v = v0; v <= v1; ++v) {
    const double y = v;
    double xl = std::numeric_limits<double>::infinity(), xr = -xl;
    for (size_t i = 0; i < poly.size(); ++i) {
      // Evaluate each edge from its upper end, so that two polygons sharing it agree exactly.
      const Eigen::Vector2d* a = &poly[i];
      const Eigen::Vector2d* b = &poly[(i + 1) % poly.size()];
      if (a->y() > b->y() || (a->y() == b->y() && a->x() > b->x())) std::swap(a, b);
      if (!(y >= a->y() && y < b->y())) continue;  // half-open: each row crosses an edge once
      const double x = a->x() + (y - a->y()) * (b->x() - a->x()) / (b->y() - a->y());
      xl = std::min(xl, x), xr = std::max(xr, x);
    }
    if (!(xr > xl)) continue;
    const int u0 = std::max(0, static_cast<int>(std::ceil(xl)));
    const int u1 = std::min(w - 1, static_cast<int>(std::ceil(xr)) - 1);
    float* depth = inverse_depth_.data() + static_cast<size_t>(v) * w;
    uint16_t* ids = ids_.data() + static_cast<size_t>(v) * w;
    const float row = vs.inv_b * static_cast<float>(v) + vs.inv_c;
    // Branch-free, so the compiler vectorises the depth test.
    for (int u = u0; u <= u1; ++u) {
      const float inv = vs.inv_a * static_cast<float>(u) + row;
      const bool nearer = inv > depth[u];
      depth[u] = nearer ? inv : depth[u];
      ids[u] = nearer ? id : ids[u];
    }
  }
}

}  // namespace kestrel::sim
