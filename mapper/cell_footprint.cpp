#include "mapper/cell_footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/numbers.h"

namespace kestrel::mapper {

namespace {

// Inclusive index range [lo, hi] of the pixels whose centre (at integer coordinates) lies in
// [a, b], clamped to [0, n). The corners were grown by the margin, which covers rounding.
void pixel_range(double a, double b, int n, int& lo, int& hi) {
  // lo = max(ceil(a), 0), hi = min(floor(b), n - 1), by truncation (std::ceil and std::floor
  // are long sequences on the baseline x86-64 target) once a and b are known to be in range.
  if (a > n + 1.0 || b < -1.0) {  // outside the image (a NaN never comes here)
    lo = 0;
    hi = -1;
    return;
  }
  if (!(a > 0.0)) {
    lo = 0;
  } else {
    const int t = static_cast<int>(a);  // 0 < a <= n + 1
    lo = t + (static_cast<double>(t) < a ? 1 : 0);
  }
  if (!(b < n - 1.0)) {
    hi = n - 1;
  } else if (b < 0.0) {
    hi = -1;  // floor of [-1, 0)
  } else {
    hi = static_cast<int>(b);  // 0 <= b < n - 1
  }
}

bool same_camera(const PinholeCamera& a, const PinholeCamera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy;
}
}  // namespace

void FootprintProjector::begin(const Scan& scan) {
  cols_ = scan.cols;
  rows_ = scan.rows;
  camera_ = scan.camera;
  const PinholeCamera& c = scan.camera;
  Eigen::Matrix3d K;
  K << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0;
  R_camera_world_ = scan.T_world_camera.linear().transpose();
  t_camera_world_ = -R_camera_world_ * scan.T_world_camera.translation();
  P_.leftCols<3>() = K * R_camera_world_;
  P_.col(3) = K * t_camera_world_;
  for (int a = 0; a < 3; ++a) origin_[a] = static_cast<double>(scan.origin(a));
  margin_ = 1e-4 + 1e-6 * static_cast<double>(scan.origin.norm());
  ray_x_.resize(static_cast<size_t>(cols_));
  ray_y_.resize(static_cast<size_t>(rows_));
  column_dir_.resize(static_cast<size_t>(cols_));
  row_dir_.resize(static_cast<size_t>(rows_));
  const Eigen::Matrix3d R_world_camera = scan.T_world_camera.linear();
  double max_x2 = 0.0, max_y2 = 0.0;
  for (int u = 0; u < cols_; ++u) {
    const double x = (u - c.cx) / c.fx;
    ray_x_[static_cast<size_t>(u)] = x;
    column_dir_[static_cast<size_t>(u)] = R_world_camera.col(0) * x;
    max_x2 = std::max(max_x2, x * x);
  }
  for (int v = 0; v < rows_; ++v) {
    const double y = (v - c.cy) / c.fy;
    ray_y_[static_cast<size_t>(v)] = y;
    row_dir_[static_cast<size_t>(v)] = R_world_camera.col(1) * y + R_world_camera.col(2);
    max_y2 = std::max(max_y2, y * y);
  }
  max_dir_norm_ = std::sqrt(1.0 + max_x2 + max_y2) * (1.0 + 1e-12);
  if (!have_tiles_ || !same_camera(tile_camera_, c)) make_tiles(c);
  // Float rounding moves OctoMap's origin and points by about 6e-8 of their coordinates;
  // 1e-5 m plus 1e-7 of the origin's distance from 0 bounds that with a wide margin.
  line_error_ = 1e-5 + 1e-7 * static_cast<double>(scan.origin.norm());
}

void FootprintProjector::make_tiles(const PinholeCamera& c) {
  // Tile cones: the axis through the tile's middle, and the widest angle to a ray through any
  // of its pixels' corners (a tile is convex in the image, so its corners bound it). They
  // depend on the camera model only.
  tiles_x_ = (cols_ + kTilePixels - 1) / kTilePixels;
  const int tiles_y = (rows_ + kTilePixels - 1) / kTilePixels;
  tiles_.resize(static_cast<size_t>(tiles_x_) * tiles_y);
  auto direction = [&](double u, double v) {
    return Eigen::Vector3d((u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0).normalized();
  };
  for (int tj = 0; tj < tiles_y; ++tj) {
    for (int ti = 0; ti < tiles_x_; ++ti) {
      const double u0 = ti * kTilePixels - 0.5, v0 = tj * kTilePixels - 0.5;
      const double u1 = std::min(u0 + kTilePixels, cols_ - 0.5), v1 = std::min(v0 + kTilePixels, rows_ - 0.5);
      Tile& t = tiles_[static_cast<size_t>(tj) * tiles_x_ + ti];
      t.axis = direction(0.5 * (u0 + u1), 0.5 * (v0 + v1));
      double cos_half = 1.0;
      for (const double u : {u0, u1}) {
        for (const double v : {v0, v1}) cos_half = std::min(cos_half, t.axis.dot(direction(u, v)));
      }
      cos_half = std::max(-1.0, cos_half - 1e-9);
      t.cos_half = cos_half;
      t.sin_half = std::sqrt(std::max(0.0, 1.0 - cos_half * cos_half));
    }
  }
  tile_camera_ = c;
  have_tiles_ = true;
}

bool FootprintProjector::certainly_clears(const Key& cell, int u, int v, double s_end_lo) const {
  // Parameter s = camera depth along the pixel's direction d (camera-z component 1), so
  // distance = s |d|. OctoMap's ray lies within line_error + 1e-6 distance of the pixel's
  // line (footprint header), and its walk's crossing times are off by far less than that;
  // in s along axis a that is (line_error + 2e-6 s |d|) / |d_a|.
  const Eigen::Vector3d d = column_dir_[static_cast<size_t>(u)] + row_dir_[static_cast<size_t>(v)];
  double in = -kInf, out = kInf, out_outer = kInf, start = 0.0;
  for (int a = 0; a < 3; ++a) {
    const double da = d[a];
    if (!(std::fabs(da) > 1e-6)) return false;  // nearly parallel to a face: leave it to the exact tests
    const double inv = 1.0 / da;
    const double t0 = (keys_.lower(cell[a]) - origin_[a]) * inv;
    const double t1 = (keys_.upper(cell[a]) - origin_[a]) * inv;
    const double s_in = std::min(t0, t1), s_out = std::max(t0, t1);
    const double scale = std::fabs(inv);
    const double tol = (line_error_ + 2e-6 * max_dir_norm_ * std::max(std::fabs(s_in), std::fabs(s_out))) * scale;
    in = std::max(in, s_in + tol);
    out = std::min(out, s_out - tol);
    out_outer = std::min(out_outer, s_out + tol);
    start = std::max(start, line_error_ * scale);
  }
  return std::max(in, start) < out && out_outer < s_end_lo;
}

bool FootprintProjector::slabs_may_clear(const CellFootprint& f, int u, int v,
                                         float reach) const {
  const Eigen::Vector3d d = column_dir_[static_cast<size_t>(u)] + row_dir_[static_cast<size_t>(v)];
  const double norm = d.norm();
  double outer_in = -kInf, outer_out = kInf, inner_out = kInf;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-12 * norm) {
      if (origin_[a] < f.lo[a] - line_error_ || origin_[a] > f.hi[a] + line_error_) return false;
      continue;
    }
    const double inv = norm / d[a];  // time = distance along the ray
    const double t0 = (f.lo[a] - origin_[a]) * inv, t1 = (f.hi[a] - origin_[a]) * inv;
    const double t_in = std::min(t0, t1), t_out = std::max(t0, t1);
    // The direction is off by a relative 1e-6 at most, so the offset grows with the time.
    const double tol = (line_error_ + 1e-6 * std::max(std::fabs(t_in), std::fabs(t_out))) *
                       std::fabs(inv);
    outer_in = std::max(outer_in, t_in - tol);
    outer_out = std::min(outer_out, t_out + tol);
    inner_out = std::min(inner_out, t_out - tol);
  }
  // outer_out < 0: the cell lies behind the camera along this line (the walk starts at 0).
  return outer_in <= outer_out && outer_out >= 0.0 && inner_out <= static_cast<double>(reach);
}

bool FootprintProjector::centre_pixel(const Key& cell, int& u, int& v) const {
  const Eigen::Vector3d centre(keys_.centre(cell[0]), keys_.centre(cell[1]), keys_.centre(cell[2]));
  const Eigen::Vector3d h = P_.leftCols<3>() * centre + P_.col(3);
  if (!(h.z() > 0.0)) return false;
  // Nearest pixel, rounding halves up (a plain cast truncates, which is floor here; std::round
  // is a library call on the baseline x86-64 target).
  const double ur = h.x() / h.z() + 0.5, vr = h.y() / h.z() + 0.5;
  if (!(ur >= 0.0 && vr >= 0.0 && ur < cols_ && vr < rows_)) return false;
  u = static_cast<int>(ur);
  v = static_cast<int>(vr);
  return true;
}

CellFootprint FootprintProjector::footprint(const Key& cell) const {
  CellFootprint f = rectangle(cell);
  if (f.empty()) return f;
  const Eigen::Vector3d centre(keys_.centre(cell[0]), keys_.centre(cell[1]), keys_.centre(cell[2]));
  complete(f, R_camera_world_ * centre + t_camera_world_);
  return f;
}

CellFootprint FootprintProjector::rectangle(const Key& cell) const {
  CellFootprint f;
  double lo[3], hi[3], gap[3];
  bool origin_near = true;
  for (int a = 0; a < 3; ++a) {
    f.lo[a] = lo[a] = keys_.lower(cell[a]);
    f.hi[a] = hi[a] = keys_.upper(cell[a]);
    gap[a] = std::max({lo[a] - origin_[a], origin_[a] - hi[a], 0.0});
    if (gap[a] > 2.0 * margin_) origin_near = false;
  }
  // A ray clears the cell only if its length reaches the cell's exit, which lies on a face the
  // ray can leave through: for axis a, the upper face unless the origin is above it, the lower
  // face unless the origin is below it. The nearest such face bounds every exit distance.
  double exit2 = kInf;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    const double others = gap[b] * gap[b] + gap[c] * gap[c];
    if (origin_[a] < hi[a]) exit2 = std::min(exit2, (hi[a] - origin_[a]) * (hi[a] - origin_[a]) + others);
    if (origin_[a] > lo[a]) exit2 = std::min(exit2, (origin_[a] - lo[a]) * (origin_[a] - lo[a]) + others);
  }
  f.min_reach = static_cast<float>(std::sqrt(exit2) - margin_);

  const double res = keys_.resolution();

  // The image of the grown cell: its corners in front of the camera project normally; where
  // the cell crosses the camera plane, its image reaches to infinity in the direction of the
  // crossing points' (x, y). If the camera centre is (nearly) on the cell, it is everywhere.
  double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
  bool any = false;
  auto towards_infinity = [&](double x, double y) {
    if (x > 0.0) umax = kInf;
    if (x < 0.0) umin = -kInf;
    if (y > 0.0) vmax = kInf;
    if (y < 0.0) vmin = -kInf;
    any = true;
  };
  if (origin_near) {
    umin = vmin = -kInf;
    umax = vmax = kInf;
    any = true;
  } else {
    // The grown cell's corners: one projected, the others by adding the projected edges
    // (corner c = corner c without its lowest bit + the edge of that bit), in scalars.
    const double side = res + 2.0 * margin_;
    const double ex[3] = {P_(0, 0) * side, P_(0, 1) * side, P_(0, 2) * side};
    const double ey[3] = {P_(1, 0) * side, P_(1, 1) * side, P_(1, 2) * side};
    const double ez[3] = {P_(2, 0) * side, P_(2, 1) * side, P_(2, 2) * side};
    const Eigen::Vector3d h0 =
        P_.leftCols<3>() * Eigen::Vector3d(lo[0] - margin_, lo[1] - margin_, lo[2] - margin_) + P_.col(3);
    double x[8], y[8], z[8];
    x[0] = h0.x();
    y[0] = h0.y();
    z[0] = h0.z();
    auto add = [&](int c, int from, int axis) {
      x[c] = x[from] + ex[axis];
      y[c] = y[from] + ey[axis];
      z[c] = z[from] + ez[axis];
    };
    add(1, 0, 0);
    add(2, 0, 1);
    add(3, 2, 0);
    add(4, 0, 2);
    add(5, 4, 0);
    add(6, 4, 1);
    add(7, 6, 0);
    // Widens the image box by corner c, which lies in front of the camera.
    const auto project = [&](int c) {
      const double inv = 1.0 / z[c];
      const double u = x[c] * inv, v = y[c] * inv;
      umin = std::min(umin, u);
      umax = std::max(umax, u);
      vmin = std::min(vmin, v);
      vmax = std::max(vmax, v);
    };
    const double z_min = std::min({z[0], z[1], z[2], z[3], z[4], z[5], z[6], z[7]});
    if (z_min > 0.0) {  // the usual case: every corner in front of the camera
      for (int c = 0; c < 8; ++c) project(c);
      any = true;
    } else {
      for (int c = 0; c < 8; ++c) {
        if (z[c] > 0.0) {
          project(c);
          any = true;
        } else if (z[c] == 0.0) {
          towards_infinity(x[c], y[c]);
        }
      }
      // Only a cell crossing the camera plane has an image reaching to infinity.
      for (int c = 0; c < 8; ++c) {
        for (int bit = 1; bit < 8; bit <<= 1) {
          if (c & bit) continue;
          const int d = c | bit;
          if ((z[c] > 0.0 && z[d] < 0.0) || (z[c] < 0.0 && z[d] > 0.0)) {
            const double s = z[c] / (z[c] - z[d]);
            towards_infinity(x[c] + s * (x[d] - x[c]), y[c] + s * (y[d] - y[c]));
          }
        }
      }
    }
  }
  if (!any) return f;  // entirely behind the camera: empty rectangle
  pixel_range(umin, umax, cols_, f.i0, f.i1);
  pixel_range(vmin, vmax, rows_, f.j0, f.j1);
  return f;
}

void FootprintProjector::complete(CellFootprint& f, const Eigen::Vector3d& centre_in_camera) const {
  f.centre_in_camera = centre_in_camera;
  const double radius = 0.5 * std::sqrt(3.0) * keys_.resolution() + 2.0 * margin_;
  f.radius2 = radius * radius;
  f.centre_distance = f.centre_in_camera.norm();
  if (f.centre_distance > radius) {
    f.sin_sphere = radius / f.centre_distance;
    f.cos_sphere = std::sqrt(1.0 - f.sin_sphere * f.sin_sphere);
  }
  // The pixel nearest the centre's image (rounding halves up; a cast truncates, which is floor
  // here), clamped into the rectangle; the rectangle's middle if the centre is not in front.
  const double z = centre_in_camera.z();
  if (z > 0.0) {
    const double inv_z = 1.0 / z;
    const double ur = camera_.fx * centre_in_camera.x() * inv_z + camera_.cx + 0.5;
    const double vr = camera_.fy * centre_in_camera.y() * inv_z + camera_.cy + 0.5;
    if (ur >= 0.0 && vr >= 0.0 && ur < cols_ && vr < rows_) {
      f.u_centre = std::clamp(static_cast<int>(ur), f.i0, f.i1);
      f.v_centre = std::clamp(static_cast<int>(vr), f.j0, f.j1);
      return;
    }
  }
  f.u_centre = (f.i0 + f.i1) / 2;
  f.v_centre = (f.j0 + f.j1) / 2;
}

}  // namespace kestrel::mapper
