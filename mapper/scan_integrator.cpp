#include "mapper/scan_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "common/error.h"
#include "mapper/reach_mask.h"

namespace kestrel::mapper {

namespace {
constexpr int kTile = kTilePixels;
constexpr int kTileLevel = 2;  // the reach pyramid's level of kTile-pixel squares
static_assert(kTile == 1 << kTileLevel);
constexpr int kNear = 1;
constexpr int kClipArea = 400;  // footprints of more pixels are clipped row by row  // the (2 kNear + 1)^2 pixels around the centre are tried first
}  // namespace

void ScanUpdate::clear() {
  free.clear();
  occupied.clear();
  rays = cells_tested = cells_witnessed = rays_traced = ray_tests = 0;
}

ScanIntegrator::ScanIntegrator(double resolution_m, const ScanOptions& options)
    : keys_(resolution_m), options_(options), projector_(keys_) {
  if (!(resolution_m > 0.0)) throw std::invalid_argument("ScanIntegrator: resolution must be > 0");
  options_.validate();
  // The cleared cells of a scan lie within max range of the camera's cell; two cells of margin
  // keep every neighbour the search looks at inside the grid.
  const int half = static_cast<int>(std::ceil(options_.max_range_m / resolution_m)) + 2;
  side_ = 2 * half + 1;
  cells_.assign(static_cast<size_t>(side_) * side_ * side_, 0);
  // The largest x with sqrt(x) <= max range (the root is monotonic and correctly rounded).
  const double max_range = options_.max_range_m;
  const double inf = std::numeric_limits<double>::infinity();
  hit_range2_ = max_range * max_range;
  while (std::sqrt(hit_range2_) > max_range) hit_range2_ = std::nextafter(hit_range2_, 0.0);
  while (std::sqrt(std::nextafter(hit_range2_, inf)) <= max_range) hit_range2_ = std::nextafter(hit_range2_, inf);
}

inline int ScanIntegrator::index(const Key& key) const {
  const int x = key[0] - base_[0], y = key[1] - base_[1], z = key[2] - base_[2];
  if (x < 0 || y < 0 || z < 0 || x >= side_ || y >= side_ || z >= side_) return -1;
  return x + side_ * (y + side_ * z);
}

inline void ScanIntegrator::mark(int idx, const Key& key, uint8_t flags) {
  if (idx < 0) return;  // cannot happen: every marked cell is within max range
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f == 0) touched_.emplace_back(idx, key);
  f = static_cast<uint8_t>(f | flags);
}

void ScanIntegrator::begin_grid(const Scan& scan) {
  scan_ = &scan;
  if (!keys_.key(scan.origin, key_origin_)) {
    throw InputError("scan at utime " + std::to_string(scan.utime) +
                     ": camera centre is outside the map's key range");
  }
  for (int a = 0; a < 3; ++a) base_[a] = key_origin_[a] - side_ / 2;
  stride_[0] = 1;
  stride_[1] = side_;
  stride_[2] = side_ * side_;
  cells_tested_ = cells_witnessed_ = rays_traced_ = ray_tests_ = 0;
}

void ScanIntegrator::begin(const Scan& scan) {
  begin_grid(scan);
  classifier_.emplace(keys_, scan.origin, key_origin_);
  built_ += 2;
  if (built_ < 2) {  // wrapped around (after 2^31 scans): forget every state
    std::fill(ray_state_.begin(), ray_state_.end(), 0u);
    built_ = 2;
  }
  queue_.clear();
  projector_.begin(scan);

  const size_t n = scan.points.size();
  if (ray_state_.size() < n) {
    ray_state_.resize(n, 0u);
    ray_slot_.resize(n);
    rays_.reserve(n);  // never reallocates during a scan: references into it stay valid
  }
  rays_.clear();
  // begin_pixels() writes every pixel's entry (no clearing pass first); the reach goes straight
  // into the pyramid's level 0.
  pixels_ = n;
  reach_ = reach_max_.level0(scan.cols, scan.rows);
  s_end_lo_.resize(n);
  end_cell_.resize(n);
  begin_pixels(scan);
  reach_max_.build_levels();
  begin_axis_parts(scan);
}

void ScanIntegrator::begin_axis_parts(const Scan& scan) {
  const Eigen::Isometry3d T_camera_world = scan.T_world_camera.inverse(Eigen::Isometry);
  const Eigen::Matrix3d R_camera_world = T_camera_world.linear();
  const Eigen::Vector3d t_camera_world = T_camera_world.translation();
  const double origin[3] = {static_cast<double>(scan.origin.x()), static_cast<double>(scan.origin.y()),
                            static_cast<double>(scan.origin.z())};
  quick_margin_ = projector_.margin();
  box_half_ = R_camera_world.cwiseAbs().rowwise().sum() *
              ((0.5 * keys_.resolution() + quick_margin_) * (1.0 + 1e-9));
  for (int a = 0; a < 3; ++a) {
    std::vector<AxisPart>& parts = axis_part_[a];
    parts.resize(static_cast<size_t>(side_));
    for (int g = 0; g < side_; ++g) {
      const uint16_t k = static_cast<uint16_t>(base_[a] + g);
      AxisPart& part = parts[static_cast<size_t>(g)];
      const Eigen::Vector3d c = R_camera_world.col(a) * keys_.centre(k) + (a == 0 ? t_camera_world : Eigen::Vector3d::Zero());
      for (int r = 0; r < 3; ++r) part.camera[r] = c[r];
      // As FootprintProjector::footprint()'s min_reach, regrouped: exit2 = sum of gap2 + min over
      // the axes of (exit2 along the axis - its gap2).
      const double lo = keys_.lower(k), hi = keys_.upper(k);
      const double gap = std::max({lo - origin[a], origin[a] - hi, 0.0});
      double exit2 = std::numeric_limits<double>::infinity();
      if (origin[a] < hi) exit2 = std::min(exit2, (hi - origin[a]) * (hi - origin[a]));
      if (origin[a] > lo) exit2 = std::min(exit2, (origin[a] - lo) * (origin[a] - lo));
      part.gap2 = gap * gap;
      part.exit_minus_gap2 = exit2 - part.gap2;
    }
  }
}

void ScanIntegrator::begin_pixels(const Scan& scan) {
  // Per ray: its hit's cell (occupied), an upper bound of its length (pruning the exact
  // search) and a lower bound of its end's camera depth (the witness test), all from the
  // float point and origin exactly as OctoMap's make-ray rule sees them (ray.h).
  const double max_range = options_.max_range_m;
  const Eigen::Vector3d z_axis = scan.T_world_camera.linear().col(2);
  const double line = projector_.line_error();
  // A cut ray's end may leave the key range (and then clears nothing) only for a camera
  // within max range of the range's edge; there the witness is not used.
  const double edge = KeySpace::kMaxVal * keys_.resolution() - max_range - 1.0;
  bool witness_ok = true;
  for (int a = 0; a < 3; ++a) witness_ok = witness_ok && std::fabs(static_cast<double>(scan.origin(a))) < edge;
  int last_hit = -1;
  double last_floor[3] = {0.0, 0.0, 0.0};  // floor(factor * coordinate) of last_hit's key
  double last_ceil[3] = {0.0, 0.0, 0.0};   // ... + 1
  const double factor = keys_.factor();
  // Everything the loop reads, in locals: the byte stores of mark() may alias anything, so
  // members and vector data would be reloaded for every pixel.
  const uint8_t* const valid = scan.valid.data();
  const octomap::point3d* const points = scan.points.data();
  const octomap::point3d origin = scan.origin;
  const double hit_range2 = hit_range2_;
  float* const reach_out = reach_;
  float* const s_end_lo_out = s_end_lo_.data();
  int* const end_cell_out = end_cell_.data();
  const size_t n = static_cast<size_t>(scan.cols) * static_cast<size_t>(scan.rows);
  for (size_t i = 0; i < n; ++i) {
    // Every entry is written (no clearing pass first); no ray: reach 0, no witness, no hit cell.
    float reach = 0.0f, s_lo = 0.0f;
    int end_cell = -1;
    do {
      if (!valid[i]) break;
      const octomap::point3d p = points[i];
      const octomap::point3d offset = p - origin;
      const double range2 = offset.norm_sq();  // float sum of squares: OctoMap's
      const double range = std::sqrt(range2);   // ... and its double root
      const double depth = z_axis.x() * static_cast<double>(offset.x()) +
                           z_axis.y() * static_cast<double>(offset.y()) +
                           z_axis.z() * static_cast<double>(offset.z());
      double s_end = 0.0;
      if (range2 <= hit_range2) {  // range <= max_range, without waiting for the root
        // Neighbouring pixels mostly hit the same cell: the key is floor(factor * coordinate),
        // so a point whose scaled coordinates lie in the last hit cell's [n, n + 1) has its
        // key, and the cell is marked already.
        const double sx = factor * static_cast<double>(p.x());
        const double sy = factor * static_cast<double>(p.y());
        const double sz = factor * static_cast<double>(p.z());
        if (!(last_hit >= 0 && sx >= last_floor[0] && sx < last_ceil[0] && sy >= last_floor[1] &&
              sy < last_ceil[1] && sz >= last_floor[2] && sz < last_ceil[2])) {
          Key k;
          if (!keys_.key(p, k)) break;  // OctoMap drops such a point altogether
          last_hit = index(k);
          mark(last_hit, k, kOccupied);
          for (int a = 0; a < 3; ++a) {
            last_floor[a] = static_cast<double>(static_cast<int>(k[a]) - KeySpace::kMaxVal);
            last_ceil[a] = last_floor[a] + 1.0;
          }
        }
        end_cell = last_hit;
        s_end = depth - 4.0 * line - 1e-6 * range;
      } else if (depth > 0.0) {
        const double dir_norm = range / depth * (1.0 + 1e-6);
        s_end = (max_range * (1.0 - 2e-6) - 2.0 * line) / dir_norm;
      }
      if (witness_ok && s_end > 0.0) s_lo = static_cast<float>(s_end * (1.0 - 1e-6));
      reach = static_cast<float>(std::min(range, max_range) * (1.0 + 1e-6) + 1e-6);
    } while (false);
    reach_out[i] = reach;
    s_end_lo_out[i] = s_lo;
    end_cell_out[i] = end_cell;
  }
}

inline ScanIntegrator::RayCache& ScanIntegrator::ray(size_t sample) {
  if (ray_state_[sample] < built_) {
    // Appended, not stored by pixel: the few hundred rays a scan builds stay in a few cache
    // lines instead of one cold line each in a 1.3 MB array.
    ray_slot_[sample] = static_cast<uint32_t>(rays_.size());
    RayCache& r = rays_.emplace_back();
    r.ray = make_ray(keys_, scan_->origin, key_origin_, scan_->points[sample], options_.max_range_m);
    r.bounds = classifier_->bounds(r.ray);
    ray_state_[sample] = built_;
    return r;
  }
  return rays_[ray_slot_[sample]];
}

inline void ScanIntegrator::set_cleared(int idx, const Key& key) {
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f & kCleared) return;
  if (f == 0) touched_.emplace_back(idx, key);
  f = static_cast<uint8_t>(f | kCleared | kTested);
  queue_.push_back({idx, key});
}

inline bool ScanIntegrator::witness_clears(const Key& cell, int idx, const Eigen::Vector3d& centre,
                                           float min_reach, bool& tried) {
  // The ray through the pixel nearest the cell's centre (given in the camera frame), then the
  // others of the (2 kNear + 1)^2 around it (the centre's may end in a hole of the depth or
  // before the cell).
  tried = false;
  if (!(centre.z() > 0.0)) return false;
  const PinholeCamera& cam = scan_->camera;
  const double inv_z = 1.0 / centre.z();
  // Nearest pixel, rounding halves up (a cast truncates, which is floor here).
  const double ur = cam.fx * centre.x() * inv_z + cam.cx + 0.5;
  const double vr = cam.fy * centre.y() * inv_z + cam.cy + 0.5;
  if (!(ur >= 0.0 && vr >= 0.0 && ur < scan_->cols && vr < scan_->rows)) return false;
  const int u = static_cast<int>(ur), v = static_cast<int>(vr);
  tried = true;
  const int cols = scan_->cols;
  // A ray ending in the cell never clears it (the cells of the surface: most witness tests that
  // fail would fail there, after the slab test).
  auto clears = [&](int pu, int pv) {
    const size_t s = static_cast<size_t>(pv) * cols + pu;
    return s_end_lo_[s] > 0.0f && reach_[s] >= min_reach && end_cell_[s] != idx &&
           projector_.certainly_clears(cell, pu, pv, static_cast<double>(s_end_lo_[s]));
  };
  if (clears(u, v)) return true;
  const int i0 = std::max(0, u - kNear), i1 = std::min(cols - 1, u + kNear);
  const int j0 = std::max(0, v - kNear), j1 = std::min(scan_->rows - 1, v + kNear);
  for (int pv = j0; pv <= j1; ++pv) {
    for (int pu = i0; pu <= i1; ++pu) {
      if ((pu != u || pv != v) && clears(pu, pv)) return true;
    }
  }
  return false;
}

inline void ScanIntegrator::trace_sample(size_t sample) {
  if (traced(sample)) return;
  RayCache& r = ray(sample);
  ray_state_[sample] = built_ + 1;
  ++rays_traced_;
  // Every cell the walk clears lies within max range of the origin, two cells inside the
  // grid, so its index is kept along the walk rather than recomputed from its key.
  trace_indexed(keys_, scan_->origin, key_origin_, r.ray, index(key_origin_), stride_,
                [&](const Key& k, int idx) { set_cleared(idx, k); });
}

inline bool ScanIntegrator::try_ray(size_t sample, const Key& cell, int idx) {
  if (traced(sample)) return false;  // its cells are marked already
  RayCache& r = ray(sample);
  ++ray_tests_;
  switch (classifier_->classify(r.ray, r.bounds, cell)) {
    case Verdict::kMisses:
      return false;
    case Verdict::kClears:
      // Walking the whole ray costs about as much as one more test and clears its other
      // cells too, so most neighbours need no test at all.
      trace_sample(sample);
      return true;
    case Verdict::kUnsure:
      trace_sample(sample);
      return (cells_[static_cast<size_t>(idx)] & kCleared) != 0;
  }
  return false;
}

inline bool ScanIntegrator::some_ray_may_reach(const Key& cell, float& min_reach,
                                               Eigen::Vector3d& centre) const {
  // No pixel in (a rectangle around) the cell's image has a ray reaching the cell's exit: the
  // common case behind surfaces and beside the image. Then cleared_by_some_ray() is false too
  // (every ray it accepts has a pixel in footprint(cell) and reach >= min_reach); this test
  // costs a tenth of a footprint.
  const AxisPart& x = axis_part_[0][static_cast<size_t>(cell[0] - base_[0])];
  const AxisPart& y = axis_part_[1][static_cast<size_t>(cell[1] - base_[1])];
  const AxisPart& z = axis_part_[2][static_cast<size_t>(cell[2] - base_[2])];
  // The cell's centre in the camera frame, and the camera-frame box around the grown cell.
  const double cx = x.camera[0] + y.camera[0] + z.camera[0];
  const double cy = x.camera[1] + y.camera[1] + z.camera[1];
  const double cz = x.camera[2] + y.camera[2] + z.camera[2];
  centre = Eigen::Vector3d(cx, cy, cz);
  const double z_near = cz - box_half_.z(), z_far = cz + box_half_.z();
  // A camera within 2 margins of the cell makes footprint() give the whole image; such a cell
  // reaches nearer than 2 sqrt(3) margins in depth, so it never passes this.
  min_reach = 0.0f;
  if (!(z_near > 4.0 * quick_margin_)) return true;
  const PinholeCamera& cam = scan_->camera;
  // x / z over the box: the smallest with the smallest x (over the far depth if x >= 0), the
  // largest with the largest x (over the near depth if x >= 0); 1e-6 pixel on each side covers
  // the rounding against footprint()'s corner projections. Clamped to just outside the image,
  // then floored by truncating a positive number (the rectangle may gain a column or row).
  const double inv_near = 1.0 / z_near, inv_far = 1.0 / z_far;
  const double x_lo = cx - box_half_.x(), x_hi = cx + box_half_.x();
  const double y_lo = cy - box_half_.y(), y_hi = cy + box_half_.y();
  const double cols = scan_->cols, rows = scan_->rows;
  const double u_lo = std::max(cam.fx * x_lo * (x_lo >= 0.0 ? inv_far : inv_near) + cam.cx - 1e-6, -2.0);
  const double u_hi = std::min(cam.fx * x_hi * (x_hi >= 0.0 ? inv_near : inv_far) + cam.cx + 1e-6, cols + 1.0);
  const double v_lo = std::max(cam.fy * y_lo * (y_lo >= 0.0 ? inv_far : inv_near) + cam.cy - 1e-6, -2.0);
  const double v_hi = std::min(cam.fy * y_hi * (y_hi >= 0.0 ? inv_near : inv_far) + cam.cy + 1e-6, rows + 1.0);
  if (!(u_lo <= u_hi && v_lo <= v_hi)) return false;
  const int i0 = std::max(static_cast<int>(u_lo + 3.0) - 3, 0);
  const int i1 = std::min(static_cast<int>(u_hi + 3.0) - 3, scan_->cols - 1);
  const int j0 = std::max(static_cast<int>(v_lo + 3.0) - 3, 0);
  const int j1 = std::min(static_cast<int>(v_hi + 3.0) - 3, scan_->rows - 1);
  if (i0 > i1 || j0 > j1) return false;
  // A lower bound of footprint(cell).min_reach (regrouped sums round differently: 1e-7 m
  // below covers that, and float rounding is monotonic).
  const double exit2 = x.gap2 + y.gap2 + z.gap2 +
                       std::min({x.exit_minus_gap2, y.exit_minus_gap2, z.exit_minus_gap2});
  min_reach = static_cast<float>(std::sqrt(exit2) - quick_margin_ - 1e-7);
  return reach_max_.any_at_least(i0, i1, j0, j1, min_reach);
}

bool ScanIntegrator::cleared_by_some_ray(const Key& cell, const Eigen::Vector3d& centre, int idx,
                                         bool witnesses_tried) {
  CellFootprint f = projector_.rectangle(cell);
  if (f.empty()) return false;
  // No ray in the cell's image reaches the cell's far side.
  if (!reach_max_.any_at_least(f.i0, f.i1, f.j0, f.j1, f.min_reach)) return false;
  projector_.complete(f, centre);
  const int cols = scan_->cols;
  const int tj0 = f.j0 / kTile, tj1 = f.j1 / kTile, ti0 = f.i0 / kTile, ti1 = f.i1 / kTile;
  // Rays near the centre that certainly clear it, when witness_clears() could not look (the
  // centre projects outside the image); no walk needed.
  const int near_i0 = std::max(f.i0, f.u_centre - kNear), near_i1 = std::min(f.i1, f.u_centre + kNear);
  const int near_j0 = std::max(f.j0, f.v_centre - kNear), near_j1 = std::min(f.j1, f.v_centre + kNear);
  for (int pv = witnesses_tried ? near_j1 + 1 : near_j0; pv <= near_j1; ++pv) {
    for (int pu = near_i0; pu <= near_i1; ++pu) {
      const size_t s = static_cast<size_t>(pv) * cols + pu;
      if (s_end_lo_[s] > 0.0f && reach_[s] >= f.min_reach &&
          projector_.certainly_clears(cell, pu, pv, static_cast<double>(s_end_lo_[s]))) {
        ++cells_witnessed_;
        return true;
      }
    }
  }
  // Otherwise every ray whose pixel lies in the cell's image and that reaches far enough goes
  // to the exact test, nearest the centre first (the likeliest to pass through), then the rest
  // tile by tile.
  auto candidate = [&](int pu, int pv) {
    const size_t s = static_cast<size_t>(pv) * cols + pu;
    return reach_[s] >= f.min_reach && reach_[s] > 0.0f && end_cell_[s] != idx && !traced(s) &&
           projector_.may_clear(f, pu, pv, reach_[s]);
  };
  for (int pv = near_j0; pv <= near_j1; ++pv) {
    for (int pu = near_i0; pu <= near_i1; ++pu) {
      if (candidate(pu, pv) && try_ray(static_cast<size_t>(pv) * cols + pu, cell, idx)) return true;
    }
  }
  // A large image (a cell next to the camera) is cut row by row to the pixels whose lines head
  // towards the cell (row_lo_ / row_hi_). Each tile row's four pixels are screened at once by
  // their reach (reaching4), then the rest of candidate() runs on the pixels that pass, in the
  // same order as a pixel-by-pixel scan.
  const bool clipped = (f.i1 - f.i0 + 1) * (f.j1 - f.j0 + 1) > kClipArea && clip_rows(f);
  const float min_reach = f.min_reach;
  for (int tj = tj0; tj <= tj1; ++tj) {
    for (int ti = ti0; ti <= ti1; ++ti) {
      if (reach_max_.square(kTileLevel, ti * kTile, tj * kTile) < min_reach ||
          !projector_.tile_may_pass(f, ti, tj))
        continue;
      const int u0 = ti * kTile;
      const bool whole = u0 + kTile <= cols;  // four pixels readable
      const int pv_end = std::min(f.j1, tj * kTile + kTile - 1);
      for (int pv = std::max(f.j0, tj * kTile); pv <= pv_end; ++pv) {
        int pu_begin = f.i0, pu_end = f.i1;
        if (clipped) {
          pu_begin = std::max(pu_begin, row_lo_[static_cast<size_t>(pv)]);
          pu_end = std::min(pu_end, row_hi_[static_cast<size_t>(pv)]);
        }
        unsigned mask = pixel_bits(pu_begin, pu_end, u0);
        if (pv >= near_j0 && pv <= near_j1) mask &= ~pixel_bits(near_i0, near_i1, u0);  // tried above
        if (mask == 0) continue;
        const size_t row = static_cast<size_t>(pv) * cols;
        mask &= whole ? reaching4(reach_ + row + u0, min_reach)
                      : reaching_scalar(reach_ + row + u0, cols - u0, min_reach);
        while (mask != 0) {
          const int pu = u0 + __builtin_ctz(mask);
          mask &= mask - 1;
          const size_t s = row + static_cast<size_t>(pu);
          if (end_cell_[s] != idx && !traced(s) && projector_.may_clear(f, pu, pv, reach_[s]) &&
              try_ray(s, cell, idx))
            return true;
        }
      }
    }
  }
  return false;
}

bool ScanIntegrator::clip_rows(const CellFootprint& f) {
  // Along an axis a whose slab the origin lies outside of by more than the distance between
  // OctoMap's ray and the pixel's line (and the footprint's margin), a line can only meet the
  // cell if its direction d heads towards the slab: side_a d_a > 0. In the camera frame
  // d = R (x, y, 1), x = (u - cx) / fx, so d_a is linear in u along a row: a half-line of
  // pixels, kept with one pixel to spare.
  const Eigen::Matrix3d R = scan_->T_world_camera.linear();
  const PinholeCamera& cam = scan_->camera;
  const double origin[3] = {static_cast<double>(scan_->origin.x()), static_cast<double>(scan_->origin.y()),
                            static_cast<double>(scan_->origin.z())};
  // (The 1e-6 relative error of OctoMap's direction moves a ray by at most 1e-6 of its length.)
  const double far_enough = 2.0 * (projector_.line_error() + projector_.margin()) +
                            2e-6 * options_.max_range_m + 1e-6;
  int axes[3], sides[3], n = 0;
  for (int a = 0; a < 3; ++a) {
    if (f.lo[a] - origin[a] > far_enough) {
      axes[n] = a;
      sides[n++] = 1;
    } else if (origin[a] - f.hi[a] > far_enough) {
      axes[n] = a;
      sides[n++] = -1;
    }
  }
  if (n == 0) return false;
  const size_t rows = static_cast<size_t>(scan_->rows);
  if (row_lo_.size() < rows) {
    row_lo_.resize(rows);
    row_hi_.resize(rows);
  }
  for (int v = f.j0; v <= f.j1; ++v) {
    const double y = (v - cam.cy) / cam.fy;
    double u_lo = -1e9, u_hi = 1e9;
    for (int c = 0; c < n; ++c) {
      const int a = axes[c];
      // side * (slope u + offset) > 0
      const double slope = sides[c] * R(a, 0) / cam.fx;
      const double offset = sides[c] * (R(a, 1) * y + R(a, 2) - R(a, 0) * cam.cx / cam.fx);
      if (std::fabs(slope) < 1e-12) {
        if (offset <= 0.0) u_hi = -1e9;  // the whole row heads away
        continue;
      }
      const double threshold = -offset / slope;
      if (slope > 0.0) {
        u_lo = std::max(u_lo, threshold - 1.0);
      } else {
        u_hi = std::min(u_hi, threshold + 1.0);
      }
    }
    row_lo_[static_cast<size_t>(v)] = static_cast<int>(std::clamp(std::floor(u_lo), -1.0, static_cast<double>(scan_->cols)));
    row_hi_[static_cast<size_t>(v)] = static_cast<int>(std::clamp(std::ceil(u_hi), -1.0, static_cast<double>(scan_->cols)));
  }
  return true;
}

void ScanIntegrator::grow_from_origin() {
  // The origin's cell is cleared by every ray that clears anything.
  for (size_t s = 0; s < pixels_; ++s) {
    if (reach_[s] > 0.0f && ray(s).ray.clears) {
      set_cleared(index(key_origin_), key_origin_);
      break;
    }
  }
  // The six face neighbours as grid index offsets; a cleared cell lies within max range, two
  // cells inside the grid, so its neighbours are in the grid (checked once per cell anyway).
  const int offset[6] = {-stride_[0], stride_[0], -stride_[1], stride_[1], -stride_[2], stride_[2]};
  for (size_t head = 0; head < queue_.size(); ++head) {
    const Pending from = queue_[head];
    bool interior = true;
    for (int a = 0; a < 3; ++a) {
      const int g = from.key[a] - base_[a];
      interior = interior && g >= 1 && g <= side_ - 2;
    }
    if (!interior) continue;  // never: see above
    for (int n = 0; n < 6; ++n) {
      const int idx = from.idx + offset[n];
      if (cells_[static_cast<size_t>(idx)] & kTested) continue;
      Key cell = from.key;
      cell[n >> 1] = static_cast<uint16_t>(cell[n >> 1] + ((n & 1) ? 1 : -1));
      test_cell(idx, cell);
    }
  }
}

void ScanIntegrator::test_cell(int idx, const Key& cell) {
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f == 0) touched_.emplace_back(idx, cell);
  f = static_cast<uint8_t>(f | kTested);
  ++cells_tested_;
  float min_reach = 0.0f;
  Eigen::Vector3d centre;
  if (!some_ray_may_reach(cell, min_reach, centre)) return;
  bool witnesses_tried = false;
  if (witness_clears(cell, idx, centre, min_reach, witnesses_tried)) {
    ++cells_witnessed_;
    set_cleared(idx, cell);
  } else if (cleared_by_some_ray(cell, centre, idx, witnesses_tried)) {
    set_cleared(idx, cell);
  }
}

void ScanIntegrator::collect(ScanUpdate& update) {
  for (const auto& [idx, key] : touched_) {
    uint8_t& f = cells_[static_cast<size_t>(idx)];
    if (f & kOccupied) {
      update.occupied.push_back(key);
    } else if (f & kCleared) {
      update.free.push_back(key);
    }
    f = 0;
  }
  touched_.clear();
}

inline void ScanIntegrator::touch(int idx, uint8_t flags) {
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f == 0) {
    if (touched_idx_.size() <= touched_count_) touched_idx_.resize(2 * touched_count_ + 64);
    touched_idx_[touched_count_++] = idx;
  }
  f = static_cast<uint8_t>(f | flags);
}

inline void ScanIntegrator::trace_cell_centre(const Key& key) {
  // computeDiscreteUpdate's point: the centre of the cell, each coordinate rounded to float
  // (keyToCoord), then computeUpdate's rules for it (hit or cut at max range; ray.h).
  const octomap::point3d centre(static_cast<float>(keys_.centre(key[0])),
                                static_cast<float>(keys_.centre(key[1])),
                                static_cast<float>(keys_.centre(key[2])));
  const Ray r = make_ray(keys_, scan_->origin, key_origin_, centre, options_.max_range_m);
  ++rays_traced_;
  // A hit lies within max range of the origin, and so does a cut ray's end (both are in the
  // grid), and so every cell a walk clears.
  if (!r.hit && !r.clears) return;
  const int end = index(r.key_end);
  if (r.hit) touch(end, kOccupied);
  // The walk is made later, with the others (walk_rays()).
  if (r.clears) walks_.push_back(start_index_walk(keys_, scan_->origin, key_origin_, r, index(key_origin_), end, stride_));
}

void ScanIntegrator::walk_rays() {
  if (walks_.empty()) return;
  // Every walk starts in the origin's cell.
  touch(index(key_origin_), kCleared);
  // A walk moves monotonically along each axis within the grid (at most 3 side_ cells), and the
  // list holds distinct cells of the grid.
  const size_t side = static_cast<size_t>(side_);
  const size_t most = std::min(touched_count_ + walks_.size() * (3 * side + 2), side * side * side) + 1;
  if (touched_idx_.size() < most) touched_idx_.resize(most);
  // The touched list is appended without a branch: the entry is written always and kept when
  // the cell was untouched.
  struct Mark {
    uint8_t* cells;
    int* touched;
    size_t count;
    void operator()(int idx, size_t) {
      uint8_t& f = cells[static_cast<size_t>(idx)];
      touched[count] = idx;
      count += f == 0;
      f = static_cast<uint8_t>(f | kCleared);
    }
  };
  touched_count_ = walk_index_walks(walks_.data(), walks_.size(), Mark{cells_.data(), touched_idx_.data(), touched_count_}).count;
  walks_.clear();
}

void ScanIntegrator::collect_discretized(ScanUpdate& update) {
  // The key from the grid index: idx = x + side (y + side z). (n + 0.5) / d rounded down by
  // truncation is exact here (the product's relative error, ~1e-16, is far below 0.5 / n).
  const int side = side_, side2 = side_ * side_;
  const double inv_side = 1.0 / side, inv_side2 = 1.0 / side2;
  for (size_t i = 0; i < touched_count_; ++i) {
    const int idx = touched_idx_[i];
    uint8_t& f = cells_[static_cast<size_t>(idx)];
    const uint8_t flags = f;
    f = 0;
    if (!(flags & (kOccupied | kCleared))) continue;
    const int z = static_cast<int>((idx + 0.5) * inv_side2);
    const int rest = idx - z * side2;
    const int y = static_cast<int>((rest + 0.5) * inv_side);
    const int x = rest - y * side;
    const Key key(static_cast<uint16_t>(base_[0] + x), static_cast<uint16_t>(base_[1] + y),
                  static_cast<uint16_t>(base_[2] + z));
    if (flags & kOccupied) {
      update.occupied.push_back(key);
    } else {
      update.free.push_back(key);
    }
  }
  touched_count_ = 0;
}

void ScanIntegrator::compute_discretized() {
  // One ray per distinct endpoint key. Keys inside the grid are deduplicated by a flag in it;
  // the others (readings well beyond max range, whose centres are too: only cut rays) by
  // sorting. Neighbouring pixels mostly share a key, so the previous key is checked first.
  // The previous key's cell is tested by float comparisons of the point against the cell's
  // float bounds (KeySpace::first_float), not by computing the key.
  for (int a = 0; a < 3; ++a) {
    if (float_base_[a] == base_[a] && first_float_[a].size() == static_cast<size_t>(side_) + 1) continue;
    first_float_[a].resize(static_cast<size_t>(side_) + 1);
    for (int g = 0; g <= side_; ++g) first_float_[a][static_cast<size_t>(g)] = keys_.first_float(base_[a] + g);
    float_base_[a] = base_[a];
  }
  const Scan& scan = *scan_;
  const uint8_t* const valid = scan.valid.data();
  const octomap::point3d* const points = scan.points.data();
  const size_t n = static_cast<size_t>(scan.cols) * static_cast<size_t>(scan.rows);
  far_endpoints_.clear();
  Key last;
  bool have_last = false;
  constexpr float inf = std::numeric_limits<float>::infinity();
  float lo[3] = {inf, inf, inf}, hi[3] = {-inf, -inf, -inf};  // the last key's cell (if in the grid)
  for (size_t i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    const octomap::point3d p = points[i];
    // Bitwise & on purpose: the six comparisons are all evaluated, without the branches of &&
    // (a hot per-pixel test, timed with BM_Cells/discretized). The coordinates are read first so
    // that no operand is a call, which is what clang's -Wbitwise-instead-of-logical flags.
    const float px = p.x(), py = p.y(), pz = p.z();
    if ((px >= lo[0]) & (px < hi[0]) & (py >= lo[1]) & (py < hi[1]) & (pz >= lo[2]) & (pz < hi[2])) {
      continue;
    }
    Key k;
    if (!keys_.key(p, k)) continue;  // outside the key range: see scan_integrator.h
    if (have_last && k == last) continue;
    last = k;
    have_last = true;
    const int idx = index(k);
    if (idx < 0) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = inf;
        hi[a] = -inf;
      }
      far_endpoints_.push_back(static_cast<uint64_t>(k[0]) | static_cast<uint64_t>(k[1]) << 16 |
                               static_cast<uint64_t>(k[2]) << 32);
      continue;
    }
    for (int a = 0; a < 3; ++a) {
      const size_t g = static_cast<size_t>(k[a] - base_[a]);
      lo[a] = first_float_[a][g];
      hi[a] = first_float_[a][g + 1];
    }
    if (cells_[static_cast<size_t>(idx)] & kEndpoint) continue;
    touch(idx, kEndpoint);
    endpoints_.push_back(k);
  }
  // The rays are made after the pass (their divisions and roots then overlap from ray to ray
  // instead of stalling the pass at every new cell).
  for (const Key& k : endpoints_) trace_cell_centre(k);
  endpoints_.clear();
  std::sort(far_endpoints_.begin(), far_endpoints_.end());
  far_endpoints_.erase(std::unique(far_endpoints_.begin(), far_endpoints_.end()), far_endpoints_.end());
  for (const uint64_t packed : far_endpoints_) {
    trace_cell_centre(Key(static_cast<uint16_t>(packed), static_cast<uint16_t>(packed >> 16),
                          static_cast<uint16_t>(packed >> 32)));
  }
  walk_rays();
}

void ScanIntegrator::compute(const Scan& scan, ScanUpdate& update, Method method) {
  update.clear();
  update.rays = scan.num_points;
  if (method == Method::kDiscretized) {
    begin_grid(scan);
    compute_discretized();
  } else {
    begin(scan);
  }
  if (method == Method::kRayTrace) {
    for (size_t s = 0; s < pixels_; ++s) {
      if (reach_[s] > 0.0f) trace_sample(s);
    }
  } else if (method == Method::kCellSearch) {
    grow_from_origin();
  }
  update.cells_tested = cells_tested_;
  update.cells_witnessed = cells_witnessed_;
  update.rays_traced = rays_traced_;
  update.ray_tests = ray_tests_;
  if (method == Method::kDiscretized) {
    collect_discretized(update);
  } else {
    collect(update);
  }
  scan_ = nullptr;
}

}  // namespace kestrel::mapper
