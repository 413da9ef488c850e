#include "station/map_cells.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/error.h"
#include "mapper/octree_io.h"  // and voxel_map.h: the map and its KeySpace (keys())

namespace kestrel::station {
namespace {

uint64_t cell_id(const mapper::Key& k) {
  return static_cast<uint64_t>(k[0]) | (static_cast<uint64_t>(k[1]) << 16) | (static_cast<uint64_t>(k[2]) << 32);
}

}  // namespace

CellSet occupied_cells(const mapper::VoxelMap& map, int64_t revision) {
  CellSet out;
  out.resolution_m = map.resolution();
  out.revision = revision;
  const mapper::KeySpace& keys = map.keys();
  std::vector<std::pair<uint64_t, Cell>> found;
  found.reserve(map.num_occupied());
  map.for_each_cell([&](const mapper::Key& k, float log_odds) {
    const Eigen::Vector3d lower(keys.lower(k[0]), keys.lower(k[1]), keys.lower(k[2]));
    out.known_bounds.extend(lower);
    out.known_bounds.extend(Eigen::Vector3d(keys.upper(k[0]), keys.upper(k[1]), keys.upper(k[2])));
    if (map.occupancy(log_odds) != mapper::Occupancy::kOccupied) return;
    found.push_back({cell_id(k), Cell{static_cast<float>(keys.centre(k[0])), static_cast<float>(keys.centre(k[1])),
                                      static_cast<float>(keys.centre(k[2])), static_cast<float>(map.resolution())}});
  });
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  out.ids.reserve(found.size());
  out.cells.reserve(found.size());
  for (const auto& [id, cell] : found) {
    out.ids.push_back(id);
    out.cells.push_back(cell);
  }
  return out;
}

CellSet cells_of_message(const kestrel::octomap_t& msg, const char* channel) {
  if (msg.format != kestrel::octomap_t::FORMAT_BINARY && msg.format != kestrel::octomap_t::FORMAT_FULL)
    throw InputError(std::string(channel) + ": unknown octomap format " + std::to_string(msg.format));
  if (msg.size != static_cast<int32_t>(msg.data.size()))
    throw InputError(std::string(channel) + ": size disagrees with the data");
  const auto format = msg.format == kestrel::octomap_t::FORMAT_FULL ? mapper::OctreeFormat::kFull
                                                                     : mapper::OctreeFormat::kBinary;
  const mapper::VoxelMap map = mapper::decode_octree(msg.data.data(), msg.data.size(), format, channel);
  return occupied_cells(map, msg.revision);
}

bool CellSet::occupied_at(const Eigen::Vector3d& p) const {
  if (resolution_m <= 0.0) return false;
  const mapper::KeySpace keys(resolution_m);
  mapper::Key k;
  if (!keys.key(p.x(), p.y(), p.z(), k)) return false;
  return std::binary_search(ids.begin(), ids.end(), cell_id(k));
}

bool CellSet::occupied_within(const Eigen::Vector3d& p, double radius_m) const {
  if (resolution_m <= 0.0 || !p.allFinite()) return false;
  const mapper::KeySpace keys(resolution_m);
  mapper::Key lo, hi;
  const Eigen::Vector3d r = Eigen::Vector3d::Constant(std::max(radius_m, 0.0));
  const Eigen::Vector3d a = p - r, b = p + r;
  if (!keys.key(a.x(), a.y(), a.z(), lo) || !keys.key(b.x(), b.y(), b.z(), hi)) return true;  // off the tree
  // The cells whose cubes meet the ball: those of the box around it, then the exact distance
  // from p to each cube.
  for (int x = lo[0]; x <= hi[0]; ++x) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      for (int z = lo[2]; z <= hi[2]; ++z) {
        const mapper::Key k(static_cast<uint16_t>(x), static_cast<uint16_t>(y), static_cast<uint16_t>(z));
        if (!std::binary_search(ids.begin(), ids.end(), cell_id(k))) continue;
        const Eigen::AlignedBox3d cube(Eigen::Vector3d(keys.lower(k[0]), keys.lower(k[1]), keys.lower(k[2])),
                                       Eigen::Vector3d(keys.upper(k[0]), keys.upper(k[1]), keys.upper(k[2])));
        if (cube.exteriorDistance(p) <= radius_m) return true;
      }
    }
  }
  return false;
}

CellDiff diff_cells(const CellSet& before, const CellSet& after) {
  CellDiff d;
  if (before.resolution_m != after.resolution_m || before.resolution_m <= 0.0) {
    d.reset = true;
    d.added = after.cells;
    return d;
  }
  // Both id lists are sorted: one merge pass finds what left and what came.
  size_t i = 0, j = 0;
  while (i < before.ids.size() || j < after.ids.size()) {
    if (j == after.ids.size() || (i < before.ids.size() && before.ids[i] < after.ids[j])) {
      d.removed.push_back(before.cells[i++]);
    } else if (i == before.ids.size() || after.ids[j] < before.ids[i]) {
      d.added.push_back(after.cells[j++]);
    } else {
      ++i;
      ++j;
    }
  }
  return d;
}

}  // namespace kestrel::station
