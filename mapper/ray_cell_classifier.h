#pragma once
// Does OctoMap's DDA, walking a given ray, clear a given cell? Decided from geometry with
// explicit error bounds, without walking the ray.
//
// OctoMap's walk (ray.h) steps through the cells in the order of its computed boundary
// crossing times t = (border - origin) / dir. Each computed time differs from the exact
// crossing of the cell boundary by less than a bound u (the border is offset by float(res/2)
// rounding, at most 3e-8 * res, plus accumulated double rounding, relative 1e-9 is far more
// than enough): u_a = (1e-8 + 1e-7 * res) * |1 / dir_a| + 1e-9 * |t|. With these bounds, per
// axis slab intervals give an inner interval (certainly inside the cell) and an outer one
// (possibly inside). The walk clears cell C when
//   * it is certainly inside C at some time after it starts: max(I_in, U0) < I_out,
//   * it certainly enters C before it can enter the end cell: I_in < O_in(end cell),
//   * it certainly leaves C before the ray's length: O_out < length,
// and certainly does not when C is the end cell, or the walk can never be inside C
// (O_in > O_out), or leaves C only after the length (I_out > length), or C lies behind the
// origin (O_out < -2 U0). Anything else is kUnsure and the caller walks the ray exactly.
// An axis the ray does not move along (dir_a == 0 exactly) never changes its key, so there
// C must share the origin's key.

#include <cstdint>

#include "mapper/key_space.h"
#include "mapper/ray.h"

namespace kestrel::mapper {

enum class Verdict : uint8_t { kClears, kMisses, kUnsure };

/// What the test derives from a ray, computed once per ray.
struct RayBounds {
  double inv_dir[3] = {0.0, 0.0, 0.0};  ///< 1 / dir_a (0 where step_a == 0)
  double start = 0.0;      ///< how far from t = 0 the walk's first crossings may be computed
  double end_entry = 0.0;  ///< lower bound of the time the walk may enter the end cell
  bool end_entry_known = false;  ///< end_entry is computed on first need
};

class RayCellClassifier {
 public:
  RayCellClassifier(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin);

  RayBounds bounds(const Ray& ray) const;
  /// What OctoMap's walk along `ray` does to `cell` (which must not be the origin's cell).
  Verdict classify(const Ray& ray, RayBounds& bounds, const Key& cell) const;

 private:
  struct Interval {
    double outer_in, inner_in, inner_out, outer_out;
  };
  /// False if an axis the ray does not move along excludes the cell.
  bool interval(const Ray& ray, const RayBounds& bounds, const Key& cell, Interval& out) const;
  double tolerance(double inv_dir) const { return boundary_error_ * std::fabs(inv_dir); }

  const KeySpace& keys_;
  double origin_[3];
  Key key_origin_;
  double boundary_error_;
};

}  // namespace kestrel::mapper
