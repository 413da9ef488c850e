#include "mapper/ray_cell_classifier.h"

#include <algorithm>
#include <limits>

#include "common/numbers.h"

namespace kestrel::mapper {

namespace {
constexpr double kRelativeError = 1e-9;
}  // namespace

RayCellClassifier::RayCellClassifier(const KeySpace& keys, const octomap::point3d& origin,
                         const Key& key_origin)
    : keys_(keys),
      origin_{static_cast<double>(origin.x()), static_cast<double>(origin.y()),
              static_cast<double>(origin.z())},
      key_origin_(key_origin),
      boundary_error_(1e-8 + 1e-7 * keys.resolution()) {}

RayBounds RayCellClassifier::bounds(const Ray& ray) const {
  RayBounds b;
  double largest = 0.0;
  for (int a = 0; a < 3; ++a) {
    b.inv_dir[a] = ray.step[a] != 0 ? 1.0 / static_cast<double>(ray.dir(a)) : 0.0;
    largest = std::max(largest, std::fabs(b.inv_dir[a]));
  }
  b.start = tolerance(largest);
  return b;
}

bool RayCellClassifier::interval(const Ray& ray, const RayBounds& bounds, const Key& cell,
                           Interval& out) const {
  out = {-kInf, -kInf, kInf, kInf};
  for (int a = 0; a < 3; ++a) {
    if (ray.step[a] == 0) {
      if (cell[a] != key_origin_[a]) return false;
      continue;
    }
    const double inv = bounds.inv_dir[a];
    const double t0 = (keys_.lower(cell[a]) - origin_[a]) * inv;
    const double t1 = (keys_.upper(cell[a]) - origin_[a]) * inv;
    const double t_in = std::min(t0, t1);
    const double t_out = std::max(t0, t1);
    const double u = tolerance(inv) + kRelativeError * std::max(std::fabs(t_in), std::fabs(t_out));
    out.outer_in = std::max(out.outer_in, t_in - u);
    out.inner_in = std::max(out.inner_in, t_in + u);
    out.inner_out = std::min(out.inner_out, t_out - u);
    out.outer_out = std::min(out.outer_out, t_out + u);
  }
  return true;
}

Verdict RayCellClassifier::classify(const Ray& ray, RayBounds& bounds, const Key& cell) const {
  if (!ray.clears || cell == ray.key_end) return Verdict::kMisses;
  Interval s;
  if (!interval(ray, bounds, cell, s)) return Verdict::kMisses;
  const double length = static_cast<double>(ray.length);
  if (s.outer_in > s.outer_out || s.inner_out > length || s.outer_out < -2.0 * bounds.start) {
    return Verdict::kMisses;
  }
  if (std::max(s.inner_in, bounds.start) < s.inner_out && s.outer_out < length) {
    if (!bounds.end_entry_known) {
      Interval end;
      bounds.end_entry = interval(ray, bounds, ray.key_end, end) && end.outer_in <= end.outer_out
                             ? end.outer_in
                             : kInf;
      bounds.end_entry_known = true;
    }
    if (s.inner_in < bounds.end_entry) return Verdict::kClears;
  }
  return Verdict::kUnsure;
}

}  // namespace kestrel::mapper
