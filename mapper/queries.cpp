#include "mapper/queries.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/numbers.h"

namespace kestrel::mapper {

namespace {

double point_to_box(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return outside.norm();
}
}  // namespace

MapQueries::MapQueries(const VoxelMap& map, const QueryOptions& options)
    : map_(map), options_(options) {}

bool MapQueries::blocked(const Key& key) const {
  switch (map_.occupancy(key)) {
    case Occupancy::kOccupied:
      return true;
    case Occupancy::kFree:
      return false;
    case Occupancy::kUnknown:
      return !options_.unknown_is_free;
  }
  return true;
}

double MapQueries::point_to_cell(const Eigen::Vector3d& p, const Key& key) const {
  const KeySpace& k = map_.keys();
  return point_to_box(p, {k.lower(key[0]), k.lower(key[1]), k.lower(key[2])},
                      {k.upper(key[0]), k.upper(key[1]), k.upper(key[2])});
}

double MapQueries::segment_to_cell(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                   const Key& key) const {
  const KeySpace& k = map_.keys();
  const Eigen::Vector3d lo(k.lower(key[0]), k.lower(key[1]), k.lower(key[2]));
  const Eigen::Vector3d hi(k.upper(key[0]), k.upper(key[1]), k.upper(key[2]));
  // The distance from a + t (b - a) to a convex set is convex in t: a ternary search finds
  // its minimum; 80 steps shrink the bracket by (2/3)^80 ~ 1e-14 of the segment's length.
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector3d d = b - a;
  for (int i = 0; i < 80 && (t1 - t0) * d.norm() > 1e-10; ++i) {
    const double m0 = t0 + (t1 - t0) / 3.0, m1 = t1 - (t1 - t0) / 3.0;
    if (point_to_box(a + m0 * d, lo, hi) <= point_to_box(a + m1 * d, lo, hi)) {
      t1 = m1;
    } else {
      t0 = m0;
    }
  }
  return point_to_box(a + 0.5 * (t0 + t1) * d, lo, hi);
}

bool MapQueries::segment_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              double radius_m) const {
  if (!(radius_m >= 0.0) || !std::isfinite(radius_m)) {
    throw std::invalid_argument("segment_free: radius must be finite and >= 0");
  }
  if (!a.allFinite() || !b.allFinite()) return false;
  const KeySpace& keys = map_.keys();
  const Eigen::Vector3d lo = a.cwiseMin(b).array() - radius_m;
  const Eigen::Vector3d hi = a.cwiseMax(b).array() + radius_m;
  Key k_lo, k_hi;
  if (!keys.key(lo.x(), lo.y(), lo.z(), k_lo) || !keys.key(hi.x(), hi.y(), hi.z(), k_hi)) return false;

  const double half_diagonal = 0.5 * std::sqrt(3.0) * keys.resolution();
  const Eigen::Vector3d d = b - a;
  const double length2 = d.squaredNorm();
  Key key;
  for (int z = k_lo[2]; z <= k_hi[2]; ++z) {
    key[2] = static_cast<uint16_t>(z);
    for (int y = k_lo[1]; y <= k_hi[1]; ++y) {
      key[1] = static_cast<uint16_t>(y);
      for (int x = k_lo[0]; x <= k_hi[0]; ++x) {
        key[0] = static_cast<uint16_t>(x);
        // Cheap bounds first: the centre's distance to the segment is within half a
        // diagonal of the cube's.
        const Eigen::Vector3d c(keys.centre(key[0]), keys.centre(key[1]), keys.centre(key[2]));
        const double t = length2 > 0.0 ? std::clamp((c - a).dot(d) / length2, 0.0, 1.0) : 0.0;
        const double centre_distance = (a + t * d - c).norm();
        if (centre_distance > radius_m + half_diagonal) continue;
        if (!blocked(key)) continue;
        if (centre_distance <= radius_m || segment_to_cell(a, b, key) <= radius_m) return false;
      }
    }
  }
  return true;
}

double MapQueries::distance_to_occupied(const Eigen::Vector3d& p, double max_distance_m) const {
  const KeySpace& keys = map_.keys();
  Key origin;
  if (!p.allFinite() || !keys.key(p.x(), p.y(), p.z(), origin)) return kInf;
  const int rings = static_cast<int>(std::ceil(max_distance_m / keys.resolution())) + 1;
  double best = kInf;
  // Cells at Chebyshev key distance k are at least (k - 1) cells away from p: after ring k,
  // nothing farther out can beat a distance <= k * resolution.
  for (int k = 0; k <= rings; ++k) {
    auto visit = [&](int dx, int dy, int dz) {
      const int x = origin[0] + dx, y = origin[1] + dy, z = origin[2] + dz;
      if (x < 0 || y < 0 || z < 0 || x > 0xffff || y > 0xffff || z > 0xffff) return;
      const Key key(static_cast<uint16_t>(x), static_cast<uint16_t>(y), static_cast<uint16_t>(z));
      if (map_.occupancy(key) != Occupancy::kOccupied) return;
      best = std::min(best, point_to_cell(p, key));
    };
    for (int dz = -k; dz <= k; ++dz) {
      for (int dy = -k; dy <= k; ++dy) {
        if (std::abs(dz) == k || std::abs(dy) == k) {
          for (int dx = -k; dx <= k; ++dx) visit(dx, dy, dz);
        } else {
          visit(-k, dy, dz);
          if (k != 0) visit(k, dy, dz);
        }
      }
    }
    if (best <= k * keys.resolution()) break;
  }
  return best <= max_distance_m ? best : kInf;
}

}  // namespace kestrel::mapper
