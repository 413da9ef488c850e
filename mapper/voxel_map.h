#pragma once
// The occupancy map: one float log-odds per 3-D cell, unknown cells kept as unknown.
//
// Cells follow OctoMap's model exactly (key_space.h addressing, OctoMap's log-odds of the hit
// and miss probabilities, clamping, "occupied when log-odds >= threshold"), and an update is
// the same float arithmetic as OccupancyOcTreeBase::updateNodeLogOdds, so the map equals, value
// for value, the OcTree that OctoMap builds from the same scans. It is stored in hashed bricks
// of 8x8x8 cells rather than in the OcTree itself, because updating a cell is then an array
// access (about 5 ns) instead of a 16-level tree descent with pruning (about 150 ns, most of
// OctoMap's insertion time); to_octree() (octree_io.h) builds the OcTree, which is identical
// to OctoMap's own, for publication and files.
//
// Forgetting (MapOptions::decay_half_life_s > 0) multiplies every log-odds by
// 2^(-dt / half_life) as sensor time advances and forgets cells whose magnitude falls below
// forget_below, so evidence that is no longer renewed fades (a moved obstacle clears even where
// no ray passes any more). With it off (default) the map is OctoMap's.
//
// Invariant: every stored value is finite and within [clamp_min, clamp_max] in log-odds.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>

#include "mapper/key_space.h"
#include "mapper/options.h"
#include "mapper/scan_integrator.h"

namespace kestrel::mapper {

enum class Occupancy : uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

class VoxelMap {
 public:
  static constexpr int kBrickBits = 3;
  static constexpr int kBrickSize = 1 << kBrickBits;
  static constexpr int kBrickCells = kBrickSize * kBrickSize * kBrickSize;

  /// Throws std::invalid_argument (naming the field) for bad options.
  explicit VoxelMap(const MapOptions& options = {});
  /// Deep copies (the rebuild's checkpoints are copies of the map).
  VoxelMap(const VoxelMap& other);
  VoxelMap& operator=(const VoxelMap& other);
  /// Moves leave `other` empty.
  VoxelMap(VoxelMap&& other) noexcept;
  VoxelMap& operator=(VoxelMap&& other) noexcept;

  const MapOptions& options() const { return options_; }
  const KeySpace& keys() const { return keys_; }
  double resolution() const { return keys_.resolution(); }
  // The model in log-odds, as OctoMap stores it (float).
  float hit() const { return hit_; }
  float miss() const { return miss_; }
  float clamp_min() const { return clamp_min_; }
  float clamp_max() const { return clamp_max_; }
  float occupied_threshold() const { return threshold_; }

  /// Applies one scan: a miss to every free cell, a hit to every occupied one. `utime` is the
  /// scan's sensor time; it drives forgetting when enabled.
  void integrate(const ScanUpdate& update, int64_t utime);
  /// One update (the hit or miss log-odds, or any value) to one cell.
  void update(const Key& key, float log_odds_change);
  /// Sets a cell's log-odds (clamped), e.g. when reading a file.
  void set(const Key& key, float log_odds);
  /// Makes a cell unknown.
  void erase(const Key& key);
  void clear();

  std::optional<float> log_odds(const Key& key) const;
  Occupancy occupancy(const Key& key) const;
  Occupancy occupancy(float log_odds) const {
    return log_odds >= threshold_ ? Occupancy::kOccupied : Occupancy::kFree;
  }
  /// The cell holding a world point (kUnknown outside the key range).
  Occupancy occupancy_at(const Eigen::Vector3d& p) const;

  /// Applies forgetting up to `utime` (no effect when off or when time goes backwards).
  void decay_to(int64_t utime);

  /// Calls f(key, log_odds) for every known cell (in no particular order).
  template <class F>
  void for_each_cell(F&& f) const {
    for (const auto& [id, brick] : bricks_) {
      const Key base = brick_base(id);
      for (int i = 0; i < kBrickCells; ++i) {
        const float v = brick->log_odds[static_cast<size_t>(i)];
        if (v == v) f(cell_key(base, i), v);  // NaN marks unknown cells
      }
    }
  }

  size_t num_cells() const { return num_cells_; }
  size_t num_occupied() const;
  size_t num_bricks() const { return bricks_.size(); }
  /// Bytes held by the cells and the hash table.
  size_t memory_bytes() const;
  /// Smallest and largest key of the known cells along each axis; false if the map is empty.
  bool key_bounds(Key& min, Key& max) const;
  /// Sensor time of the newest scan integrated (0 before the first).
  int64_t utime() const { return utime_; }

 private:
  struct Brick {
    std::array<float, kBrickCells> log_odds;
    int known = 0;
  };
  struct IdHash {
    size_t operator()(uint64_t id) const {
      id ^= id >> 31;
      id *= 0x9e3779b97f4a7c15ULL;
      return static_cast<size_t>(id ^ (id >> 29));
    }
  };
  static uint64_t brick_id(const Key& k) {
    return static_cast<uint64_t>(k[0] >> kBrickBits) |
           static_cast<uint64_t>(k[1] >> kBrickBits) << 13 |
           static_cast<uint64_t>(k[2] >> kBrickBits) << 26;
  }
  static int cell_index(const Key& k) {
    constexpr int m = kBrickSize - 1;
    return (k[0] & m) | (k[1] & m) << kBrickBits | (k[2] & m) << (2 * kBrickBits);
  }
  static Key brick_base(uint64_t id) {
    constexpr uint64_t m = (1u << 13) - 1;
    return Key(static_cast<uint16_t>((id & m) << kBrickBits),
               static_cast<uint16_t>(((id >> 13) & m) << kBrickBits),
               static_cast<uint16_t>(((id >> 26) & m) << kBrickBits));
  }
  static Key cell_key(const Key& base, int i) {
    constexpr int m = kBrickSize - 1;
    return Key(static_cast<uint16_t>(base[0] + (i & m)),
               static_cast<uint16_t>(base[1] + ((i >> kBrickBits) & m)),
               static_cast<uint16_t>(base[2] + ((i >> (2 * kBrickBits)) & m)));
  }
  float* cell(const Key& key, bool create);
  inline float* lookup(const Key& key, bool create);  // cell(), inlined within voxel_map.cpp
  inline void apply(const Key& key, float change);     // update(), inlined within voxel_map.cpp
  float clamp(float v) const { return v < clamp_min_ ? clamp_min_ : (v > clamp_max_ ? clamp_max_ : v); }

  MapOptions options_;
  KeySpace keys_;
  float hit_, miss_, clamp_min_, clamp_max_, threshold_;
  std::unordered_map<uint64_t, std::unique_ptr<Brick>, IdHash> bricks_;
  // A direct-mapped cache of recently used bricks in front of the hash table: a scan updates a
  // few thousand cells in a few dozen bricks, not brick by brick. Emptied whenever a brick goes.
  struct CacheSlot {
    uint64_t id;
    Brick* brick;
  };
  static constexpr size_t kCacheSlots = 64;
  static size_t cache_slot(uint64_t id) { return (id ^ (id >> 11) ^ (id >> 22)) & (kCacheSlots - 1); }
  void forget_cache();
  std::array<CacheSlot, kCacheSlots> cache_;
  uint64_t last_id_ = ~0ULL;  // the brick of the last cell() call
  Brick* last_brick_ = nullptr;
  size_t num_cells_ = 0;
  int64_t utime_ = 0;
  int64_t decay_utime_ = -1;  // time the decay was last applied (-1: never)
};

}  // namespace kestrel::mapper
