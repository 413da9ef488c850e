#include "mapper/scan_integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "common/error.h"

namespace kestrel::mapper {

namespace {
constexpr int kTile = kTilePixels;
constexpr int kNear = 2;  // the (2 kNear + 1)^2 pixels around the centre are tried first
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
}

int ScanIntegrator::index(const Key& key) const {
  const int x = key[0] - base_[0], y = key[1] - base_[1], z = key[2] - base_[2];
  if (x < 0 || y < 0 || z < 0 || x >= side_ || y >= side_ || z >= side_) return -1;
  return x + side_ * (y + side_ * z);
}

void ScanIntegrator::mark(const Key& key, uint8_t flags) {
  const int idx = index(key);
  if (idx < 0) return;  // cannot happen: every marked cell is within max range
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f == 0) touched_.emplace_back(idx, key);
  f = static_cast<uint8_t>(f | flags);
}

void ScanIntegrator::begin(const Scan& scan) {
  scan_ = &scan;
  if (!keys_.key(scan.origin, key_origin_)) {
    throw InputError("scan at utime " + std::to_string(scan.utime) +
                     ": camera centre is outside the map's key range");
  }
  for (int a = 0; a < 3; ++a) base_[a] = key_origin_[a] - side_ / 2;
  stride_[0] = 1;
  stride_[1] = side_;
  stride_[2] = side_ * side_;
  classifier_.emplace(keys_, scan.origin, key_origin_);
  ++epoch_;
  cells_tested_ = cells_witnessed_ = rays_traced_ = ray_tests_ = 0;
  queue_.clear();
  projector_.begin(scan);

  const size_t n = scan.points.size();
  if (rays_.size() < n) rays_.resize(n);
  reach_.assign(n, 0.0f);
  s_end_lo_.assign(n, 0.0f);
  end_cell_.assign(n, -1);
  const int tiles_x = (scan.cols + kTile - 1) / kTile;
  const int tiles_y = (scan.rows + kTile - 1) / kTile;
  tile_reach_.assign(static_cast<size_t>(tiles_x) * tiles_y, 0.0f);
  begin_pixels(scan);
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
  const int tiles_x = (scan.cols + kTile - 1) / kTile;
  for (int v = 0; v < scan.rows; ++v) {
    float* tile_row = &tile_reach_[static_cast<size_t>(v / kTile) * tiles_x];
    for (int u = 0; u < scan.cols; ++u) {
      const size_t i = static_cast<size_t>(v) * scan.cols + u;
      if (!scan.valid[i]) continue;
      const octomap::point3d& p = scan.points[i];
      const octomap::point3d offset = p - scan.origin;
      const double range = offset.norm();  // float sum of squares, double root: OctoMap's
      const double depth = z_axis.x() * static_cast<double>(offset.x()) +
                           z_axis.y() * static_cast<double>(offset.y()) +
                           z_axis.z() * static_cast<double>(offset.z());
      double s_end = 0.0;
      if (range <= max_range) {
        Key k;
        if (!keys_.key(p, k)) continue;  // OctoMap drops such a point altogether
        mark(k, kOccupied);
        end_cell_[i] = index(k);
        s_end = depth - 4.0 * line - 1e-6 * range;
      } else if (depth > 0.0) {
        const double dir_norm = range / depth * (1.0 + 1e-6);
        s_end = (max_range * (1.0 - 2e-6) - 2.0 * line) / dir_norm;
      }
      if (witness_ok && s_end > 0.0) s_end_lo_[i] = static_cast<float>(s_end * (1.0 - 1e-6));
      const float reach = static_cast<float>(std::min(range, max_range) * (1.0 + 1e-6) + 1e-6);
      reach_[i] = reach;
      float& tile = tile_row[u / kTile];
      tile = std::max(tile, reach);
    }
  }
}

ScanIntegrator::RayCache& ScanIntegrator::ray(size_t sample) {
  RayCache& r = rays_[sample];
  if (r.epoch != epoch_) {
    r.ray = make_ray(keys_, scan_->origin, key_origin_, scan_->points[sample], options_.max_range_m);
    r.bounds = classifier_->bounds(r.ray);
    r.epoch = epoch_;
    r.traced = false;
  }
  return r;
}

void ScanIntegrator::set_cleared(int idx, const Key& key) {
  uint8_t& f = cells_[static_cast<size_t>(idx)];
  if (f & kCleared) return;
  if (f == 0) touched_.emplace_back(idx, key);
  f = static_cast<uint8_t>(f | kCleared | kTested);
  queue_.push_back({idx, key});
}

bool ScanIntegrator::witness_clears(const Key& cell) {
  int u = 0, v = 0;
  if (!projector_.centre_pixel(cell, u, v)) return false;
  const float s_end = s_end_lo_[static_cast<size_t>(v) * scan_->cols + u];
  return s_end > 0.0f && projector_.certainly_clears(cell, u, v, s_end);
}

void ScanIntegrator::trace_sample(size_t sample) {
  RayCache& r = ray(sample);
  if (r.traced) return;
  r.traced = true;
  ++rays_traced_;
  trace(keys_, scan_->origin, key_origin_, r.ray, [&](const Key& k) {
    const int idx = index(k);
    if (idx >= 0) set_cleared(idx, k);
  });
}

bool ScanIntegrator::try_ray(size_t sample, const Key& cell, int idx) {
  RayCache& r = ray(sample);
  if (r.traced) return false;  // its cells are marked already
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

bool ScanIntegrator::cleared_by_some_ray(const Key& cell, int idx) {
  const CellFootprint f = projector_.footprint(cell);
  if (f.empty()) return false;
  const int cols = scan_->cols;
  const int tiles_x = (cols + kTile - 1) / kTile;
  const int tj0 = f.j0 / kTile, tj1 = f.j1 / kTile, ti0 = f.i0 / kTile, ti1 = f.i1 / kTile;
  // No ray in the cell's image reaches the cell's far side: the common case behind surfaces.
  bool reaches = false;
  for (int tj = tj0; tj <= tj1 && !reaches; ++tj) {
    for (int ti = ti0; ti <= ti1; ++ti) {
      if (tile_reach_[static_cast<size_t>(tj) * tiles_x + ti] >= f.min_reach) {
        reaches = true;
        break;
      }
    }
  }
  if (!reaches) return false;
  // Rays near the centre that certainly clear it (the witness missed through a hole in the
  // depth or at the image border); no walk needed.
  const int near_i0 = std::max(f.i0, f.u_centre - kNear), near_i1 = std::min(f.i1, f.u_centre + kNear);
  const int near_j0 = std::max(f.j0, f.v_centre - kNear), near_j1 = std::min(f.j1, f.v_centre + kNear);
  for (int pv = near_j0; pv <= near_j1; ++pv) {
    for (int pu = near_i0; pu <= near_i1; ++pu) {
      const size_t s = static_cast<size_t>(pv) * cols + pu;
      if (s_end_lo_[s] > 0.0f && reach_[s] >= f.min_reach &&
          projector_.certainly_clears(cell, pu, pv, s_end_lo_[s])) {
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
    return reach_[s] >= f.min_reach && reach_[s] > 0.0f && end_cell_[s] != idx &&
           projector_.may_clear(f, pu, pv, reach_[s]);
  };
  for (int pv = near_j0; pv <= near_j1; ++pv) {
    for (int pu = near_i0; pu <= near_i1; ++pu) {
      if (candidate(pu, pv) && try_ray(static_cast<size_t>(pv) * cols + pu, cell, idx)) return true;
    }
  }
  for (int tj = tj0; tj <= tj1; ++tj) {
    for (int ti = ti0; ti <= ti1; ++ti) {
      if (tile_reach_[static_cast<size_t>(tj) * tiles_x + ti] < f.min_reach ||
          !projector_.tile_may_pass(f, ti, tj))
        continue;
      const int pv_end = std::min(f.j1, tj * kTile + kTile - 1);
      const int pu_end = std::min(f.i1, ti * kTile + kTile - 1);
      for (int pv = std::max(f.j0, tj * kTile); pv <= pv_end; ++pv) {
        const bool near_row = pv >= near_j0 && pv <= near_j1;
        for (int pu = std::max(f.i0, ti * kTile); pu <= pu_end; ++pu) {
          if (near_row && pu >= near_i0 && pu <= near_i1) continue;  // tried above
          if (candidate(pu, pv) && try_ray(static_cast<size_t>(pv) * cols + pu, cell, idx))
            return true;
        }
      }
    }
  }
  return false;
}

void ScanIntegrator::grow_from_origin() {
  // The origin's cell is cleared by every ray that clears anything.
  for (size_t s = 0; s < reach_.size(); ++s) {
    if (reach_[s] > 0.0f && ray(s).ray.clears) {
      set_cleared(index(key_origin_), key_origin_);
      break;
    }
  }
  for (size_t head = 0; head < queue_.size(); ++head) {
    const Pending from = queue_[head];
    for (int n = 0; n < 6; ++n) {
      const int axis = n >> 1;
      const int step = (n & 1) ? 1 : -1;
      const int k = from.key[axis] + step;
      // Cleared cells lie within max range, two cells inside the grid; this never fails.
      if (k - base_[axis] < 0 || k - base_[axis] >= side_) continue;
      const int idx = from.idx + step * stride_[axis];
      uint8_t& f = cells_[static_cast<size_t>(idx)];
      if (f & kTested) continue;
      Key cell = from.key;
      cell[axis] = static_cast<uint16_t>(k);
      if (f == 0) touched_.emplace_back(idx, cell);
      f = static_cast<uint8_t>(f | kTested);
      ++cells_tested_;
      if (witness_clears(cell)) {
        ++cells_witnessed_;
        set_cleared(idx, cell);
      } else if (cleared_by_some_ray(cell, idx)) {
        set_cleared(idx, cell);
      }
    }
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

void ScanIntegrator::compute(const Scan& scan, ScanUpdate& update, Method method) {
  update.clear();
  update.rays = scan.num_points;
  begin(scan);
  if (method == Method::kRayTrace) {
    for (size_t s = 0; s < reach_.size(); ++s) {
      if (reach_[s] > 0.0f) trace_sample(s);
    }
  } else {
    grow_from_origin();
  }
  update.cells_tested = cells_tested_;
  update.cells_witnessed = cells_witnessed_;
  update.rays_traced = rays_traced_;
  update.ray_tests = ray_tests_;
  collect(update);
  scan_ = nullptr;
}

}  // namespace kestrel::mapper
