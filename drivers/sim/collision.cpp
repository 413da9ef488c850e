#include "drivers/sim/collision.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/numbers.h"

namespace kestrel::sim {
namespace {

// Minimum of a convex function of u in [0, 1] by golden-section search; distances from a
// moving point to a convex set are convex along a segment, so this is exact.
template <class F>
double minimize_convex(F f) {
  constexpr double g = 0.6180339887498949;
  double lo = 0.0, hi = 1.0;
  double u1 = hi - g * (hi - lo), u2 = lo + g * (hi - lo);
  double f1 = f(u1), f2 = f(u2);
  for (int i = 0; i < 48 && hi - lo > 1e-10; ++i) {
    if (f1 < f2) {
      hi = u2, u2 = u1, f2 = f1;
      u1 = hi - g * (hi - lo), f1 = f(u1);
    } else {
      lo = u1, u1 = u2, f1 = f2;
      u2 = lo + g * (hi - lo), f2 = f(u2);
    }
  }
  return std::min({f1, f2, f(0.0), f(1.0)});
}

bool segment_crosses_rectangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Surface& s) {
  const double da = s.plane_distance(a), db = s.plane_distance(b);
  if ((da > 0) == (db > 0) && da != 0 && db != 0) return false;
  const double u = da == db ? 0.0 : da / (da - db);
  const Eigen::Vector3d q = a + u * (b - a) - s.origin;
  const double x = q.dot(s.axis_s), y = q.dot(s.axis_t);
  return x >= 0 && x <= s.width && y >= 0 && y <= s.height;
}

}  // namespace

Eigen::AlignedBox3d bounds_of(const Surface& s) {
  Eigen::AlignedBox3d b;
  for (const auto& c : s.corners()) b.extend(c);
  return b;
}

Eigen::AlignedBox3d bounds_of(const Box& box) {
  Eigen::AlignedBox3d b;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner((i & 1 ? 1 : -1) * box.half_extent.x(), (i & 2 ? 1 : -1) * box.half_extent.y(),
                                 (i & 4 ? 1 : -1) * box.half_extent.z());
    b.extend(box.T_world_box * corner);
  }
  return b;
}

double ray_box_local(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& half_extent,
                     int* axis) {
  double t_near = -kInf, t_far = kInf;
  int entry = -1;
  for (int i = 0; i < 3; ++i) {
    const double h = half_extent[i];
    if (std::abs(d[i]) < 1e-15) {
      if (std::abs(o[i]) > h) return kInf;
      continue;
    }
    double t0 = (-h - o[i]) / d[i], t1 = (h - o[i]) / d[i];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) t_near = t0, entry = i;
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_near <= 0.0 || entry < 0) return kInf;
  *axis = entry;
  return t_near;
}

double ray_box(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Box& box, int* face) {
  const Eigen::Isometry3d T_box_world = box.T_world_box.inverse();
  const Eigen::Vector3d d = T_box_world.linear() * dir;
  int axis = -1;
  const double t = ray_box_local(T_box_world * origin, d, box.half_extent, &axis);
  // Entering through the face whose normal opposes the direction.
  if (t < kInf) *face = 2 * axis + (d[axis] < 0 ? 0 : 1);
  return t;
}

double ray_rectangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Surface& s) {
  const double denom = s.normal.dot(dir);
  if (std::abs(denom) < 1e-15) return kInf;
  const double t = s.normal.dot(s.origin - origin) / denom;
  if (t <= 0.0) return kInf;
  const Eigen::Vector3d q = origin + t * dir - s.origin;
  const double u = q.dot(s.axis_s), v = q.dot(s.axis_t);
  return (u >= 0 && u <= s.width && v >= 0 && v <= s.height) ? t : kInf;
}

double distance_to_rectangle(const Eigen::Vector3d& p, const Surface& s) {
  const Eigen::Vector3d d = p - s.origin;
  const double u = std::clamp(d.dot(s.axis_s), 0.0, s.width);
  const double v = std::clamp(d.dot(s.axis_t), 0.0, s.height);
  return (d - u * s.axis_s - v * s.axis_t).norm();
}

double distance_to_box(const Eigen::Vector3d& p, const Box& box) {
  const Eigen::Vector3d local = box.T_world_box.inverse() * p;
  return (local.cwiseAbs() - box.half_extent).cwiseMax(0.0).norm();
}

double segment_distance_to_rectangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Surface& s) {
  if (segment_crosses_rectangle(a, b, s)) return 0.0;
  return minimize_convex([&](double u) { return distance_to_rectangle(a + u * (b - a), s); });
}

double segment_distance_to_box(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Box& box) {
  return minimize_convex([&](double u) { return distance_to_box(a + u * (b - a), box); });
}

CollisionIndex::CollisionIndex(const std::vector<Surface>& surfaces, const std::vector<Box>& boxes)
    : boxes_(boxes) {
  for (const Surface& s : surfaces)
    if (s.box < 0) rectangles_.push_back(s);
  std::vector<std::pair<Item, Eigen::AlignedBox3d>> items;
  for (size_t i = 0; i < rectangles_.size(); ++i)
    items.push_back({{false, static_cast<int>(i)}, bounds_of(rectangles_[i])});
  for (size_t i = 0; i < boxes_.size(); ++i) items.push_back({{true, static_cast<int>(i)}, bounds_of(boxes_[i])});
  Eigen::AlignedBox3d all;
  for (const auto& it : items) all.extend(it.second);
  if (items.empty()) return;
  origin_x_ = all.min().x();
  origin_y_ = all.min().y();
  nx_ = std::max(1, static_cast<int>(std::ceil((all.max().x() - origin_x_) / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((all.max().y() - origin_y_) / cell_)));
  cells_.assign(static_cast<size_t>(nx_) * ny_, {});
  for (const auto& [item, b] : items) {
    const int ix0 = std::clamp(static_cast<int>((b.min().x() - origin_x_) / cell_), 0, nx_ - 1);
    const int ix1 = std::clamp(static_cast<int>((b.max().x() - origin_x_) / cell_), 0, nx_ - 1);
    const int iy0 = std::clamp(static_cast<int>((b.min().y() - origin_y_) / cell_), 0, ny_ - 1);
    const int iy1 = std::clamp(static_cast<int>((b.max().y() - origin_y_) / cell_), 0, ny_ - 1);
    if ((ix1 - ix0 + 1) * (iy1 - iy0 + 1) > 256) {  // floors, ceilings: check always
      global_.push_back(item);
      continue;
    }
    for (int y = iy0; y <= iy1; ++y)
      for (int x = ix0; x <= ix1; ++x) cells_[static_cast<size_t>(y) * nx_ + x].push_back(item);
  }
}

std::vector<CollisionIndex::Item> CollisionIndex::candidates(double x0, double y0, double x1, double y1) const {
  std::vector<Item> out = global_;
  if (nx_ == 0) return out;
  const int ix0 = std::clamp(static_cast<int>(std::floor((x0 - origin_x_) / cell_)), 0, nx_ - 1);
  const int ix1 = std::clamp(static_cast<int>(std::floor((x1 - origin_x_) / cell_)), 0, nx_ - 1);
  const int iy0 = std::clamp(static_cast<int>(std::floor((y0 - origin_y_) / cell_)), 0, ny_ - 1);
  const int iy1 = std::clamp(static_cast<int>(std::floor((y1 - origin_y_) / cell_)), 0, ny_ - 1);
  for (int y = iy0; y <= iy1; ++y)
    for (int x = ix0; x <= ix1; ++x) {
      const auto& c = cells_[static_cast<size_t>(y) * nx_ + x];
      out.insert(out.end(), c.begin(), c.end());
    }
  std::sort(out.begin(), out.end(), [](const Item& a, const Item& b) {
    return a.is_box != b.is_box ? a.is_box < b.is_box : a.index < b.index;
  });
  out.erase(std::unique(out.begin(), out.end(),
                        [](const Item& a, const Item& b) { return a.is_box == b.is_box && a.index == b.index; }),
            out.end());
  return out;
}

double CollisionIndex::clearance(const Eigen::Vector3d& p, double cap) const {
  double best = cap;
  for (const Item& it : candidates(p.x() - cap, p.y() - cap, p.x() + cap, p.y() + cap)) {
    const double d = it.is_box ? distance_to_box(p, boxes_[it.index]) : distance_to_rectangle(p, rectangles_[it.index]);
    best = std::min(best, d);
    if (best <= 0.0) break;
  }
  return best;
}

double CollisionIndex::segment_clearance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double cap) const {
  const Eigen::Vector3d mid = 0.5 * (a + b);
  const double half = 0.5 * (b - a).norm();
  double best = cap;
  const Eigen::Vector3d lo = a.cwiseMin(b), hi = a.cwiseMax(b);
  for (const Item& it : candidates(lo.x() - cap, lo.y() - cap, hi.x() + cap, hi.y() + cap)) {
    // Cheap bound first: the segment lies within `half` of its midpoint.
    const double dm = it.is_box ? distance_to_box(mid, boxes_[it.index]) : distance_to_rectangle(mid, rectangles_[it.index]);
    if (dm - half >= best) continue;
    const double d = it.is_box ? segment_distance_to_box(a, b, boxes_[it.index])
                               : segment_distance_to_rectangle(a, b, rectangles_[it.index]);
    best = std::min(best, d);
    if (best <= 0.0) break;
  }
  return best;
}

std::optional<RayHit> CollisionIndex::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                              double max_distance) const {
  const Eigen::Vector3d end = origin + max_distance * direction;
  const Eigen::Vector3d lo = origin.cwiseMin(end), hi = origin.cwiseMax(end);
  RayHit best{max_distance, -1};
  for (const Item& it : candidates(lo.x(), lo.y(), hi.x(), hi.y())) {
    if (it.is_box) {
      int face = -1;
      const double t = ray_box(origin, direction, boxes_[it.index], &face);
      if (t <= best.distance) best = {t, boxes_[it.index].faces[face]};
    } else {
      const double t = ray_rectangle(origin, direction, rectangles_[it.index]);
      if (t <= best.distance) best = {t, rectangles_[it.index].id};
    }
  }
  if (best.surface < 0) return std::nullopt;
  return best;
}

}  // namespace kestrel::sim
