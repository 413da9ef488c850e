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

/// The state of trace_indexed()'s walk for a ray whose end cell lies in the index's grid (then
/// index equality is key equality, and every cell the walk visits lies within the ray's length
/// of the origin, in the grid too), kept by grid index alone: crossing times, their steps, the
/// length, the current and the end cell's index, and the index step by the axis chosen (0 z,
/// 1 x, 2 y).
struct IndexWalk {
  double t[3];
  double delta[3];
  double length;
  int index;
  int end;
  int move[4];
};

/// The walk of `ray` (ray.clears) at its first cell, the origin's (origin_index); end_index is
/// the index of ray.key_end. The same arithmetic as trace_indexed() (and so OctoMap's).
inline IndexWalk start_index_walk(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
                                  const Ray& ray, int origin_index, int end_index, const int index_step[3]) {
  IndexWalk w;
  const double res = keys.resolution();
  for (int a = 0; a < 3; ++a) {
    if (ray.step[a] != 0) {
      double border = keys.centre(key_origin[a]);
      border += static_cast<double>(static_cast<float>(ray.step[a] * res * 0.5));
      const double d = static_cast<double>(ray.dir(a));
      w.t[a] = (border - static_cast<double>(origin(a))) / d;
      w.delta[a] = res / std::fabs(d);
    } else {
      w.t[a] = std::numeric_limits<double>::max();
      w.delta[a] = std::numeric_limits<double>::max();
    }
  }
  w.length = static_cast<double>(ray.length);
  w.index = origin_index;
  w.end = end_index;
  w.move[0] = ray.step[2] * index_step[2];
  w.move[1] = ray.step[0] * index_step[0];
  w.move[2] = ray.step[1] * index_step[1];
  w.move[3] = 0;
  return w;
}

/// Continues walk `w` from its current cell to the end: visit(index) for every further cell the
/// ray clears, in order. Each step picks its axis without a branch (the choice is
/// unpredictable): the crossing times of the axes not chosen get + 0.0, which leaves them
/// unchanged, so the arithmetic and the choice are OctoMap's, as in trace_indexed().
template <class Visit>
void continue_index_walk(IndexWalk& w, Visit&& visit) {
  double tx = w.t[0], ty = w.t[1], tz = w.t[2];
  const double dx = w.delta[0], dy = w.delta[1], dz = w.delta[2];
  int index = w.index;
  for (;;) {
    const bool x_below_y = tx < ty;
    const bool step_x = x_below_y & (tx < tz);
    const bool step_y = !x_below_y & (ty < tz);
    const bool step_z = !(step_x | step_y);
    index += w.move[static_cast<int>(step_x) | static_cast<int>(step_y) << 1];
    tx += step_x ? dx : 0.0;
    ty += step_y ? dy : 0.0;
    tz += step_z ? dz : 0.0;
    if (index == w.end) break;
    if (std::min(std::min(tx, ty), tz) > w.length) break;
    visit(index);
  }
  w.t[0] = tx;
  w.t[1] = ty;
  w.t[2] = tz;
  w.index = index;
}

/// Walks walks[0..count) (each at its first cell, which is not visited again) to their ends:
/// visit(index, k) for every further cell walk k clears, in order for each walk; the walks are
/// interleaved (two at a time in SSE2 lanes, so that one walk's dependent steps overlap the
/// other's), each with the same steps as continue_index_walk(). `visit` is taken and returned
/// by value (kept in registers: its stores cannot alias it). Changes the walks.
template <class Visit>
Visit walk_index_walks(IndexWalk* walks, size_t count, Visit visit) {
#ifdef __SSE2__
  if (count == 0) return visit;
  // Lane 0 walks walks[a], lane 1 walks[b]; a finished lane takes the next walk, or goes dead
  // (crossing times 0 past a negative length: finished at every step, never visited).
  constexpr size_t kDead = ~size_t{0};
  static constexpr int kNoMove[4] = {0, 0, 0, 0};
  size_t a = 0, b = count >= 2 ? 1 : kDead;
  size_t next = count >= 2 ? 2 : 1;
  const IndexWalk dead = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, -1.0, 0, 0, {0, 0, 0, 0}};
  const IndexWalk& wb = b == kDead ? dead : walks[b];
  __m128d tx = _mm_set_pd(wb.t[0], walks[a].t[0]), ty = _mm_set_pd(wb.t[1], walks[a].t[1]),
          tz = _mm_set_pd(wb.t[2], walks[a].t[2]);
  __m128d dx = _mm_set_pd(wb.delta[0], walks[a].delta[0]), dy = _mm_set_pd(wb.delta[1], walks[a].delta[1]),
          dz = _mm_set_pd(wb.delta[2], walks[a].delta[2]);
  __m128d length = _mm_set_pd(wb.length, walks[a].length);
  int index_a = walks[a].index, index_b = wb.index;
  int end_a = walks[a].end, end_b = b == kDead ? 0 : wb.end;
  const int* move_a = walks[a].move;
  const int* move_b = b == kDead ? kNoMove : wb.move;
  for (;;) {
    const __m128d x_below_y = _mm_cmplt_pd(tx, ty);
    const __m128d step_x = _mm_and_pd(x_below_y, _mm_cmplt_pd(tx, tz));
    const __m128d step_y = _mm_andnot_pd(x_below_y, _mm_cmplt_pd(ty, tz));
    tx = _mm_add_pd(tx, _mm_and_pd(step_x, dx));
    ty = _mm_add_pd(ty, _mm_and_pd(step_y, dy));
    tz = _mm_add_pd(tz, _mm_andnot_pd(_mm_or_pd(step_x, step_y), dz));
    const int bits_x = _mm_movemask_pd(step_x), bits_y = _mm_movemask_pd(step_y);
    index_a += move_a[(bits_x & 1) | (bits_y & 1) << 1];
    index_b += move_b[(bits_x >> 1) | (bits_y & 2)];
    const int past = _mm_movemask_pd(_mm_cmpgt_pd(_mm_min_pd(_mm_min_pd(tx, ty), tz), length));
    const bool done_a = index_a == end_a || (past & 1);
    const bool done_b = index_b == end_b || (past & 2);
    if (!(done_a | done_b)) {
      visit(index_a, a);
      visit(index_b, b);
      continue;
    }
    if (!done_a) visit(index_a, a);
    if (!done_b) visit(index_b, b);
    if (done_a && a != kDead) {
      const IndexWalk& w = next < count ? walks[next] : dead;
      a = next < count ? next++ : kDead;
      tx = _mm_move_sd(tx, _mm_set_sd(w.t[0]));
      ty = _mm_move_sd(ty, _mm_set_sd(w.t[1]));
      tz = _mm_move_sd(tz, _mm_set_sd(w.t[2]));
      dx = _mm_move_sd(dx, _mm_set_sd(w.delta[0]));
      dy = _mm_move_sd(dy, _mm_set_sd(w.delta[1]));
      dz = _mm_move_sd(dz, _mm_set_sd(w.delta[2]));
      length = _mm_move_sd(length, _mm_set_sd(w.length));
      index_a = w.index;
      end_a = w.end;
      move_a = a == kDead ? kNoMove : w.move;
    }
    if (done_b && b != kDead) {
      const IndexWalk& w = next < count ? walks[next] : dead;
      b = next < count ? next++ : kDead;
      tx = _mm_shuffle_pd(tx, _mm_set_sd(w.t[0]), 0);
      ty = _mm_shuffle_pd(ty, _mm_set_sd(w.t[1]), 0);
      tz = _mm_shuffle_pd(tz, _mm_set_sd(w.t[2]), 0);
      dx = _mm_shuffle_pd(dx, _mm_set_sd(w.delta[0]), 0);
      dy = _mm_shuffle_pd(dy, _mm_set_sd(w.delta[1]), 0);
      dz = _mm_shuffle_pd(dz, _mm_set_sd(w.delta[2]), 0);
      length = _mm_shuffle_pd(length, _mm_set_sd(w.length), 0);
      index_b = w.index;
      end_b = w.end;
      move_b = b == kDead ? kNoMove : w.move;
    }
    if (a == kDead && b == kDead) return visit;
  }
#else
  for (size_t k = 0; k < count; ++k) continue_index_walk(walks[k], [&](int index) { visit(index, k); });
  return visit;
#endif
}

/// trace_indexed() for a ray whose end cell lies in the index's grid (end_index is its index),
/// by grid index alone: visit(index) for every cell the ray clears, in order.
template <class Visit>
void trace_index_only(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
                      const Ray& ray, int origin_index, int end_index, const int index_step[3],
                      Visit&& visit) {
  if (!ray.clears) return;
  IndexWalk w = start_index_walk(keys, origin, key_origin, ray, origin_index, end_index, index_step);
  visit(w.index);
  continue_index_walk(w, visit);
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
