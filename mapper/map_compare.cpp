#include "mapper/map_compare.h"

#include <cmath>
#include <stdexcept>

namespace kestrel::mapper {

namespace {
bool occupied_near(const VoxelMap& map, const Key& k, int tolerance) {
  for (int dz = -tolerance; dz <= tolerance; ++dz)
    for (int dy = -tolerance; dy <= tolerance; ++dy)
      for (int dx = -tolerance; dx <= tolerance; ++dx) {
        const int x = k[0] + dx, y = k[1] + dy, z = k[2] + dz;
        if (x < 0 || y < 0 || z < 0 || x > 0xffff || y > 0xffff || z > 0xffff) continue;
        const Key n(static_cast<uint16_t>(x), static_cast<uint16_t>(y), static_cast<uint16_t>(z));
        if (map.occupancy(n) == Occupancy::kOccupied) return true;
      }
  return false;
}
}  // namespace

MapAgreement compare_maps(const VoxelMap& a, const VoxelMap& b, int tolerance_cells) {
  if (std::fabs(a.resolution() - b.resolution()) > 1e-9 * a.resolution()) {
    throw std::invalid_argument("compare_maps: the maps have different resolutions");
  }
  MapAgreement r;
  r.known_a = a.num_cells();
  r.known_b = b.num_cells();
  a.for_each_cell([&](const Key& k, float v) {
    const Occupancy ca = a.occupancy(v);
    const Occupancy cb = b.occupancy(k);
    if (cb != Occupancy::kUnknown) {
      ++r.known_both;
      r.same_class += ca == cb;
      r.free_a_occupied_b += ca == Occupancy::kFree && cb == Occupancy::kOccupied;
      r.occupied_a_free_b += ca == Occupancy::kOccupied && cb == Occupancy::kFree;
    }
    if (ca == Occupancy::kOccupied) {
      ++r.occupied_a;
      r.occupied_both += cb == Occupancy::kOccupied;
      r.occupied_a_matched += occupied_near(b, k, tolerance_cells);
    }
  });
  b.for_each_cell([&](const Key& k, float v) {
    if (b.occupancy(v) != Occupancy::kOccupied) return;
    ++r.occupied_b;
    r.occupied_b_matched += occupied_near(a, k, tolerance_cells);
  });
  return r;
}

}  // namespace kestrel::mapper
