#include "mapper/cell_footprint.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kestrel::mapper {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// Inclusive index range [lo, hi] of the pixels whose centre (at integer coordinates) lies in
// [a, b], clamped to [0, n). The corners were grown by the margin, which covers rounding.
void pixel_range(double a, double b, int n, int& lo, int& hi) {
  lo = a <= -1e9 ? 0 : static_cast<int>(std::max(std::ceil(a), 0.0));
  hi = b >= 1e9 ? n - 1 : static_cast<int>(std::min(std::floor(b), n - 1.0));
  if (a > n + 1.0 || b < -1.0) hi = lo - 1;
}

bool same_camera(const PinholeCamera& a, const PinholeCamera& b) {
  return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy;
}
}  // namespace

void FootprintProjector::begin(const Scan& scan) {
  cols_ = scan.cols;
  rows_ = scan.rows;
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
  const Eigen::Vector3d centre(keys_.centre(cell[0]), keys_.centre(cell[1]), keys_.centre(cell[2]));
  f.centre_in_camera = R_camera_world_ * centre + t_camera_world_;
  const double radius = 0.5 * std::sqrt(3.0) * res + 2.0 * margin_;
  f.radius2 = radius * radius;
  f.centre_distance = f.centre_in_camera.norm();
  if (f.centre_distance > radius) {
    f.sin_sphere = radius / f.centre_distance;
    f.cos_sphere = std::sqrt(1.0 - f.sin_sphere * f.sin_sphere);
  }

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
    // The grown cell's corners: one projected, the others by adding the projected edges.
    Eigen::Vector3d corner[8];
    const double side = res + 2.0 * margin_;
    const Eigen::Vector3d edge[3] = {P_.col(0) * side, P_.col(1) * side, P_.col(2) * side};
    corner[0] = P_.leftCols<3>() * Eigen::Vector3d(lo[0] - margin_, lo[1] - margin_, lo[2] - margin_) + P_.col(3);
    bool all_in_front = true;
    for (int c = 0; c < 8; ++c) {
      if (c > 0) corner[c] = corner[c & ~(c & -c)] + edge[__builtin_ctz(static_cast<unsigned>(c))];
      const Eigen::Vector3d& h = corner[c];
      if (h.z() > 0.0) {
        const double inv = 1.0 / h.z();
        const double u = h.x() * inv, v = h.y() * inv;
        umin = std::min(umin, u);
        umax = std::max(umax, u);
        vmin = std::min(vmin, v);
        vmax = std::max(vmax, v);
        any = true;
      } else {
        all_in_front = false;
        if (h.z() == 0.0) towards_infinity(h.x(), h.y());
      }
    }
    // Only a cell crossing the camera plane has an image reaching to infinity.
    for (int c = 0; c < 8 && !all_in_front; ++c) {
      for (int bit = 1; bit < 8; bit <<= 1) {
        if (c & bit) continue;
        const Eigen::Vector3d& a = corner[c];
        const Eigen::Vector3d& b = corner[c | bit];
        if ((a.z() > 0.0 && b.z() < 0.0) || (a.z() < 0.0 && b.z() > 0.0)) {
          const double s = a.z() / (a.z() - b.z());
          towards_infinity(a.x() + s * (b.x() - a.x()), a.y() + s * (b.y() - a.y()));
        }
      }
    }
  }
  if (!any) return f;  // entirely behind the camera: empty rectangle
  pixel_range(umin, umax, cols_, f.i0, f.i1);
  pixel_range(vmin, vmax, rows_, f.j0, f.j1);
  if (f.empty()) return f;
  int u = 0, v = 0;
  if (centre_pixel(cell, u, v)) {
    f.u_centre = std::clamp(u, f.i0, f.i1);
    f.v_centre = std::clamp(v, f.j0, f.j1);
  } else {
    f.u_centre = (f.i0 + f.i1) / 2;
    f.v_centre = (f.j0 + f.j1) / 2;
  }
  return f;
}

}  // namespace kestrel::mapper
