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
  rays = cells_tested = rays_traced = ray_tests = 0;
}

ScanIntegrator::ScanIntegrator(double resolution_m, const ScanOptions& options)
    : keys_(resolution_m), options_(options) {
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
  classifier_.emplace(keys_, scan.origin, key_origin_);
  ++epoch_;
  cells_tested_ = rays_traced_ = ray_tests_ = 0;
  queue_.clear();

  projector_.emplace(keys_, scan);

  const size_t n = scan.points.size();
  if (rays_.size() < n) rays_.resize(n);
  reach_.assign(n, 0.0f);
  end_cell_.assign(n, -1);
  const int tiles_x = (scan.cols + kTile - 1) / kTile;
  const int tiles_y = (scan.rows + kTile - 1) / kTile;
  tile_reach_.assign(static_cast<size_t>(tiles_x) * tiles_y, 0.0f);

  // Occupied cells, and how far each ray can reach (for pruning the cell search).
  const double max_range = options_.max_range_m;
  for (int v = 0; v < scan.rows; ++v) {
    for (int u = 0; u < scan.cols; ++u) {
      const size_t i = static_cast<size_t>(v) * scan.cols + u;
      if (!scan.valid[i]) continue;
      const octomap::point3d& p = scan.points[i];
      const double range = (p - scan.origin).norm();
      if (range <= max_range) {
        Key k;
        if (keys_.key(p, k)) {
          mark(k, kOccupied);
          end_cell_[i] = index(k);
        }
      }
      const float reach = static_cast<float>(std::min(range, max_range) * (1.0 + 1e-6) + 1e-6);
      reach_[i] = reach;
      float& tile = tile_reach_[static_cast<size_t>(v / kTile) * tiles_x + u / kTile];
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
  queue_.push_back(key);
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
  // Most cells are answered by the ray through the pixel nearest the cell's centre.
  int u = 0, v = 0;
  size_t witness = std::numeric_limits<size_t>::max();
  if (projector_->centre_pixel(cell, u, v)) {
    witness = static_cast<size_t>(v) * scan_->cols + u;
    if (reach_[witness] > 0.0f && try_ray(witness, cell, idx)) return true;
  }
  // Otherwise every ray whose pixel lies in the cell's image and that reaches far enough,
  // nearest the centre first (the likeliest to pass through), then the rest tile by tile.
  const CellFootprint f = projector_->footprint(cell);
  if (f.empty()) return false;
  const int cols = scan_->cols;
  auto candidate = [&](int pu, int pv) {
    const size_t s = static_cast<size_t>(pv) * cols + pu;
    return s != witness && reach_[s] >= f.min_reach && reach_[s] > 0.0f && end_cell_[s] != idx &&
           projector_->may_clear(f, pu, pv, reach_[s]);
  };
  const int near_i0 = std::max(f.i0, f.u_centre - kNear), near_i1 = std::min(f.i1, f.u_centre + kNear);
  const int near_j0 = std::max(f.j0, f.v_centre - kNear), near_j1 = std::min(f.j1, f.v_centre + kNear);
  for (int pv = near_j0; pv <= near_j1; ++pv) {
    for (int pu = near_i0; pu <= near_i1; ++pu) {
      if (candidate(pu, pv) && try_ray(static_cast<size_t>(pv) * cols + pu, cell, idx)) return true;
    }
  }
  const int tiles_x = (cols + kTile - 1) / kTile;
  for (int tj = f.j0 / kTile; tj <= f.j1 / kTile; ++tj) {
    for (int ti = f.i0 / kTile; ti <= f.i1 / kTile; ++ti) {
      if (tile_reach_[static_cast<size_t>(tj) * tiles_x + ti] < f.min_reach ||
          !projector_->tile_may_pass(f, ti, tj))
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
    const Key from = queue_[head];
    for (int n = 0; n < 6; ++n) {
      const int axis = n >> 1;
      const int k = from[axis] + ((n & 1) ? 1 : -1);
      if (k < 0 || k > 0xffff) continue;
      Key cell = from;
      cell[axis] = static_cast<uint16_t>(k);
      const int idx = index(cell);
      if (idx < 0) continue;
      uint8_t& f = cells_[static_cast<size_t>(idx)];
      if (f & kTested) continue;
      if (f == 0) touched_.emplace_back(idx, cell);
      f = static_cast<uint8_t>(f | kTested);
      ++cells_tested_;
      if (cleared_by_some_ray(cell, idx)) set_cleared(idx, cell);
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
  update.rays_traced = rays_traced_;
  update.ray_tests = ray_tests_;
  collect(update);
  scan_ = nullptr;
}

}  // namespace kestrel::mapper
