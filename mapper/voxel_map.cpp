#include "mapper/voxel_map.h"

#include <octomap/octomap_utils.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace kestrel::mapper {

VoxelMap::VoxelMap(const MapOptions& options)
    : options_(options), keys_(options.resolution_m) {
  options_.validate();
  // octomap::logodds rounds to float exactly as the OcTree's setters do.
  hit_ = octomap::logodds(options_.prob_hit);
  miss_ = octomap::logodds(options_.prob_miss);
  clamp_min_ = octomap::logodds(options_.clamp_min);
  clamp_max_ = octomap::logodds(options_.clamp_max);
  threshold_ = octomap::logodds(options_.occupancy_threshold);
  forget_cache();
}

void VoxelMap::forget_cache() {
  cache_.fill({~0ULL, nullptr});
  last_id_ = ~0ULL;
  last_brick_ = nullptr;
}

float* VoxelMap::cell(const Key& key, bool create) { return lookup(key, create); }

inline float* VoxelMap::lookup(const Key& key, bool create) {
  const uint64_t id = brick_id(key);
  if (id != last_id_) {
    CacheSlot& slot = cache_[cache_slot(id)];
    if (slot.id != id) {
      auto it = bricks_.find(id);
      if (it == bricks_.end()) {
        if (!create) return nullptr;
        auto brick = std::make_unique<Brick>();
        brick->log_odds.fill(std::numeric_limits<float>::quiet_NaN());
        it = bricks_.emplace(id, std::move(brick)).first;
      }
      slot = {id, it->second.get()};
    }
    last_id_ = id;
    last_brick_ = slot.brick;
  }
  return &last_brick_->log_odds[static_cast<size_t>(cell_index(key))];
}

void VoxelMap::update(const Key& key, float change) { apply(key, change); }

inline void VoxelMap::apply(const Key& key, float change) {
  float* v = lookup(key, true);
  if (*v != *v) {  // unknown: a new cell starts at 0, as a new OcTree node does
    *v = 0.0f;
    ++last_brick_->known;
    ++num_cells_;
  }
  *v = clamp(*v + change);
}

void VoxelMap::set(const Key& key, float log_odds) {
  float* v = cell(key, true);
  if (*v != *v) {
    ++last_brick_->known;
    ++num_cells_;
  }
  *v = clamp(log_odds);
}

void VoxelMap::erase(const Key& key) {
  float* v = cell(key, false);
  if (v == nullptr || *v != *v) return;
  *v = std::numeric_limits<float>::quiet_NaN();
  --num_cells_;
  if (--last_brick_->known == 0) {
    bricks_.erase(last_id_);
    forget_cache();
  }
}

VoxelMap::VoxelMap(const VoxelMap& other)
    : options_(other.options_),
      keys_(other.keys_),
      hit_(other.hit_),
      miss_(other.miss_),
      clamp_min_(other.clamp_min_),
      clamp_max_(other.clamp_max_),
      threshold_(other.threshold_),
      num_cells_(other.num_cells_),
      utime_(other.utime_),
      decay_utime_(other.decay_utime_) {
  forget_cache();
  bricks_.reserve(other.bricks_.size());
  for (const auto& [id, brick] : other.bricks_) bricks_.emplace(id, std::make_unique<Brick>(*brick));
}

VoxelMap::VoxelMap(VoxelMap&& other) noexcept : keys_(other.keys_) { *this = std::move(other); }

VoxelMap& VoxelMap::operator=(VoxelMap&& other) noexcept {
  if (this == &other) return *this;
  options_ = std::move(other.options_);
  keys_ = other.keys_;
  hit_ = other.hit_;
  miss_ = other.miss_;
  clamp_min_ = other.clamp_min_;
  clamp_max_ = other.clamp_max_;
  threshold_ = other.threshold_;
  bricks_ = std::move(other.bricks_);
  num_cells_ = other.num_cells_;
  utime_ = other.utime_;
  decay_utime_ = other.decay_utime_;
  forget_cache();
  // The source keeps no bricks, and no cache pointing at them.
  other.bricks_.clear();
  other.num_cells_ = 0;
  other.forget_cache();
  return *this;
}

VoxelMap& VoxelMap::operator=(const VoxelMap& other) {
  if (this != &other) *this = VoxelMap(other);
  return *this;
}

void VoxelMap::clear() {
  bricks_.clear();
  forget_cache();
  num_cells_ = 0;
  utime_ = 0;
  decay_utime_ = -1;
}

void VoxelMap::integrate(const ScanUpdate& update_set, int64_t utime) {
  decay_to(utime);
  if (utime > utime_) utime_ = utime;
  for (const Key& k : update_set.free) apply(k, miss_);
  for (const Key& k : update_set.occupied) apply(k, hit_);
}

std::optional<float> VoxelMap::log_odds(const Key& key) const {
  const auto it = bricks_.find(brick_id(key));
  if (it == bricks_.end()) return std::nullopt;
  const float v = it->second->log_odds[static_cast<size_t>(cell_index(key))];
  if (v != v) return std::nullopt;
  return v;
}

Occupancy VoxelMap::occupancy(const Key& key) const {
  const auto v = log_odds(key);
  return v ? occupancy(*v) : Occupancy::kUnknown;
}

Occupancy VoxelMap::occupancy_at(const Eigen::Vector3d& p) const {
  Key k;
  return keys_.key(p.x(), p.y(), p.z(), k) ? occupancy(k) : Occupancy::kUnknown;
}

void VoxelMap::decay_to(int64_t utime) {
  if (options_.decay_half_life_s <= 0.0) return;
  if (decay_utime_ < 0) {
    decay_utime_ = utime;
    return;
  }
  const double dt = 1e-6 * static_cast<double>(utime - decay_utime_);
  if (dt < options_.decay_period_s) return;
  decay_utime_ = utime;
  const float factor = static_cast<float>(std::exp2(-dt / options_.decay_half_life_s));
  const float forget = static_cast<float>(options_.forget_below);
  std::vector<uint64_t> empty;
  for (auto& [id, brick] : bricks_) {
    for (float& v : brick->log_odds) {
      if (v != v) continue;
      v *= factor;
      if (std::fabs(v) < forget) {
        v = std::numeric_limits<float>::quiet_NaN();
        --brick->known;
        --num_cells_;
      }
    }
    if (brick->known == 0) empty.push_back(id);
  }
  for (const uint64_t id : empty) bricks_.erase(id);
  forget_cache();
}

size_t VoxelMap::num_occupied() const {
  size_t n = 0;
  for_each_cell([&](const Key&, float v) { n += v >= threshold_; });
  return n;
}

size_t VoxelMap::memory_bytes() const {
  // Each brick, plus the hash node holding its id and pointer, plus the bucket array.
  const size_t node = sizeof(uint64_t) + sizeof(void*) + sizeof(void*) + sizeof(size_t);
  return bricks_.size() * (sizeof(Brick) + node) + bricks_.bucket_count() * sizeof(void*);
}

bool VoxelMap::key_bounds(Key& min, Key& max) const {
  if (num_cells_ == 0) return false;
  int lo[3] = {0xffff, 0xffff, 0xffff}, hi[3] = {0, 0, 0};
  for_each_cell([&](const Key& k, float) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<int>(k[a]));
      hi[a] = std::max(hi[a], static_cast<int>(k[a]));
    }
  });
  for (int a = 0; a < 3; ++a) {
    min[a] = static_cast<uint16_t>(lo[a]);
    max[a] = static_cast<uint16_t>(hi[a]);
  }
  return true;
}

}  // namespace kestrel::mapper
