#pragma once
// One ray exactly as OctoMap's OccupancyOcTreeBase::computeUpdate treats it, and the cells it
// clears, found by the same 3-D DDA (Amanatides & Woo) with the same float / double arithmetic
// as OcTreeBaseImpl::computeRayKeys. The fast integrator (scan_integrator.h) falls back to
// trace() whenever a ray passes too close to a cell edge for geometry alone to say what
// OctoMap would do, so these two functions are what "the same map as OctoMap" rests on.
//
// OctoMap's rules, restated:
//  * a point within max range is a hit: its cell becomes occupied and the cells from the
//    origin's up to (excluding) the point's are cleared;
//  * a point beyond max range only clears, along its direction, up to max range;
//  * the traversal stops on reaching the end cell, or when the cell it has stepped into is
//    left only after the ray's length (so that cell is not cleared either);
//  * a point or origin outside the tree's 16-bit key range contributes nothing.

#include <algorithm>
#include <cmath>
#include <limits>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <octomap/octomap_types.h>

#include "mapper/key_space.h"

namespace kestrel::mapper {

struct Ray {
  octomap::point3d end;     ///< the point, or the cut at max range
  Key key_end;
  octomap::point3d dir;     ///< (end - origin) / length, in float as OctoMap computes it
  float length = 0.0f;      ///< |end - origin|, float
  bool hit = false;         ///< the end is a measurement: its cell is occupied
  bool clears = false;      ///< the traversal adds at least the origin's cell
  int8_t step[3] = {0, 0, 0};
};

/// The ray from `origin` (whose key is `key_origin`, already checked) to the measured point `p`.
Ray make_ray(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
             const octomap::point3d& p, double max_range_m);

/// Calls visit(key, index) for every cell the ray clears, in order, starting with the origin's
/// cell, where index starts at `origin_index` and moves by index_step[a] * step_a whenever the
/// key moves along axis a (a linear index into a grid around the origin, kept without
/// recomputing it from the key for every cell).
template <class Visit>
void trace_indexed(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
                   const Ray& ray, int origin_index, const int index_step[3], Visit&& visit) {
  if (!ray.clears) return;
  const double res = keys.resolution();
  double t_max[3];
  double t_delta[3];
  for (int a = 0; a < 3; ++a) {
    if (ray.step[a] != 0) {
      // Same operations as OctoMap: the border is the cell centre plus half a cell rounded to
      // float, and the crossing times are accumulated by repeated addition below.
      double border = keys.centre(key_origin[a]);
      border += static_cast<double>(static_cast<float>(ray.step[a] * res * 0.5));
      const double d = static_cast<double>(ray.dir(a));
      t_max[a] = (border - static_cast<double>(origin(a))) / d;
      t_delta[a] = res / std::fabs(d);
    } else {
      t_max[a] = std::numeric_limits<double>::max();
      t_delta[a] = std::numeric_limits<double>::max();
    }
  }
  const double length = static_cast<double>(ray.length);
  Key key = key_origin;
  int index = origin_index;
  const int ix = ray.step[0] * index_step[0], iy = ray.step[1] * index_step[1],
            iz = ray.step[2] * index_step[2];
  visit(key, index);
  // The crossing times live in scalars, not an array indexed by the axis (which made every step
  // wait on a store and a reload); the choice of axis and the arithmetic are OctoMap's.
  double tx = t_max[0], ty = t_max[1], tz = t_max[2];
  const double dx = t_delta[0], dy = t_delta[1], dz = t_delta[2];
  for (;;) {
    if (tx < ty ? tx < tz : false) {
      key[0] = static_cast<uint16_t>(key[0] + ray.step[0]);
      index += ix;
      tx += dx;
    } else if (!(tx < ty) && ty < tz) {
      key[1] = static_cast<uint16_t>(key[1] + ray.step[1]);
      index += iy;
      ty += dy;
    } else {
      key[2] = static_cast<uint16_t>(key[2] + ray.step[2]);
      index += iz;
      tz += dz;
    }
    if (key == ray.key_end) return;
    if (std::min(std::min(tx, ty), tz) > length) return;
    visit(key, index);
  }
}

/// trace_indexed() for a ray whose end cell lies in the index's grid (end_index is its index;
/// then index equality is key equality, and every cell the walk visits lies within the ray's
/// length of the origin, in the grid too): calls visit(index) for every cell the ray clears, in
/// the same order, without keeping the key. Each step picks its axis without a branch (the
/// choice is unpredictable): the crossing times of the axes not chosen get + 0.0, which leaves
/// them unchanged, so the arithmetic and the choice are OctoMap's, as in trace_indexed().
template <class Visit>
void trace_index_only(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
                      const Ray& ray, int origin_index, int end_index, const int index_step[3],
                      Visit&& visit) {
  if (!ray.clears) return;
  const double res = keys.resolution();
  double t_max[3];
  double t_delta[3];
  for (int a = 0; a < 3; ++a) {
    if (ray.step[a] != 0) {
      double border = keys.centre(key_origin[a]);
      border += static_cast<double>(static_cast<float>(ray.step[a] * res * 0.5));
      const double d = static_cast<double>(ray.dir(a));
      t_max[a] = (border - static_cast<double>(origin(a))) / d;
      t_delta[a] = res / std::fabs(d);
    } else {
      t_max[a] = std::numeric_limits<double>::max();
      t_delta[a] = std::numeric_limits<double>::max();
    }
  }
  int index = origin_index;
  // Index step by the axis chosen: 0 z, 1 x, 2 y (the bits of the choice below).
  const int index_move[4] = {ray.step[2] * index_step[2], ray.step[0] * index_step[0],
                             ray.step[1] * index_step[1], 0};
  visit(index);
#ifdef __SSE2__
  // Scalars in the low lanes; the comparisons give all-ones masks that select the increments.
  __m128d tx = _mm_set_sd(t_max[0]), ty = _mm_set_sd(t_max[1]), tz = _mm_set_sd(t_max[2]);
  const __m128d dx = _mm_set_sd(t_delta[0]), dy = _mm_set_sd(t_delta[1]), dz = _mm_set_sd(t_delta[2]);
  const __m128d length = _mm_set_sd(static_cast<double>(ray.length));
  for (;;) {
    const __m128d x_below_y = _mm_cmplt_sd(tx, ty);
    const __m128d step_x = _mm_and_pd(x_below_y, _mm_cmplt_sd(tx, tz));
    const __m128d step_y = _mm_andnot_pd(x_below_y, _mm_cmplt_sd(ty, tz));
    const __m128d step_x_or_y = _mm_or_pd(step_x, step_y);
    tx = _mm_add_sd(tx, _mm_and_pd(step_x, dx));
    ty = _mm_add_sd(ty, _mm_and_pd(step_y, dy));
    tz = _mm_add_sd(tz, _mm_andnot_pd(step_x_or_y, dz));
    index += index_move[_mm_movemask_pd(_mm_unpacklo_pd(step_x, step_y))];
    if (index == end_index) return;
    if (_mm_comigt_sd(_mm_min_sd(_mm_min_sd(tx, ty), tz), length)) return;
    visit(index);
  }
#else
  const double length = static_cast<double>(ray.length);
  double tx = t_max[0], ty = t_max[1], tz = t_max[2];
  const double dx = t_delta[0], dy = t_delta[1], dz = t_delta[2];
  for (;;) {
    const bool x_below_y = tx < ty;
    const bool step_x = x_below_y & (tx < tz);
    const bool step_y = !x_below_y & (ty < tz);
    const bool step_z = !(step_x | step_y);
    index += index_move[static_cast<int>(step_x) | static_cast<int>(step_y) << 1];
    tx += step_x ? dx : 0.0;
    ty += step_y ? dy : 0.0;
    tz += step_z ? dz : 0.0;
    if (index == end_index) return;
    if (std::min(std::min(tx, ty), tz) > length) return;
    visit(index);
  }
#endif
}

/// Calls visit(key) for every cell the ray clears, in order, starting with the origin's cell.
template <class Visit>
void trace(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
           const Ray& ray, Visit&& visit) {
  const int no_index[3] = {0, 0, 0};
  trace_indexed(keys, origin, key_origin, ray, 0, no_index,
                [&](const Key& key, int) { visit(key); });
}

}  // namespace kestrel::mapper
