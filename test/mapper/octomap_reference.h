#pragma once
// OctoMap's own answers, for comparison: the cells computeUpdate (or computeDiscreteUpdate)
// would clear and mark occupied for a scan, and differences between those and a ScanUpdate.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <string>

#include "mapper/scan.h"
#include "mapper/scan_integrator.h"
#include "mapper/voxel_map.h"

namespace kestrel::mapper::test {

struct OctomapUpdate {
  octomap::KeySet free, occupied;
};

inline OctomapUpdate octomap_update(const Scan& scan, double resolution, double max_range) {
  octomap::OcTree tree(resolution);
  OctomapUpdate u;
  tree.computeUpdate(scan.valid_points(), scan.origin, u.free, u.occupied, max_range);
  return u;
}

/// The same for OctoMap's endpoint-discretised insertion (insertPointCloud(..., discretize =
/// true)): computeDiscreteUpdate.
inline OctomapUpdate octomap_discrete_update(const Scan& scan, double resolution, double max_range) {
  octomap::OcTree tree(resolution);
  OctomapUpdate u;
  tree.computeDiscreteUpdate(scan.valid_points(), scan.origin, u.free, u.occupied, max_range);
  return u;
}

/// Number of cells on which `mine` and OctoMap's answer differ (0 = identical sets).
inline size_t count_differences(const ScanUpdate& mine, const OctomapUpdate& theirs) {
  auto diff = [](const std::vector<Key>& a, const octomap::KeySet& b) {
    octomap::KeySet seen;
    size_t d = 0;
    for (const Key& k : a) {
      if (!seen.insert(k).second) ++d;  // duplicates count as differences too
      if (!b.count(k)) ++d;
    }
    for (const Key& k : b) d += seen.count(k) ? 0 : 1;
    return d;
  };
  return diff(mine.free, theirs.free) + diff(mine.occupied, theirs.occupied);
}

/// Asserts that every leaf of OctoMap's tree, expanded to cells, has exactly `map`'s value
/// (bit for bit: the same float arithmetic); returns the number of cells compared, which the
/// caller checks against map.num_cells() (so nothing is in one and not the other).
inline size_t expect_values_equal(const VoxelMap& map, const octomap::OcTree& reference) {
  size_t cells = 0;
  for (auto it = reference.begin_leafs(); it != reference.end_leafs(); ++it) {
    const int n = 1 << (16 - it.getDepth());
    const Key base = it.getIndexKey();
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          const auto v = map.log_odds(Key(base[0] + x, base[1] + y, base[2] + z));
          EXPECT_TRUE(v.has_value());
          if (!v) return cells;
          EXPECT_EQ(*v, it->getLogOdds());
          if (*v != it->getLogOdds()) return cells;
          ++cells;
        }
  }
  return cells;
}

}  // namespace kestrel::mapper::test
