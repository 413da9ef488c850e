#pragma once
// How far two maps of the same resolution agree, e.g. the map built from VO poses against the
// one built from ground-truth poses, or a map against the true geometry.
//
// Agreement is counted on cells both maps know; occupied cells are also matched with a
// tolerance of `tolerance_cells` (Chebyshev distance), because a pose error of a few
// centimetres moves a wall by one cell without making the map wrong for a planner.

#include <cstddef>

#include "mapper/voxel_map.h"

namespace kestrel::mapper {

struct MapAgreement {
  size_t known_a = 0, known_b = 0;
  size_t known_both = 0;
  size_t same_class = 0;          ///< known in both and the same class (free / occupied)
  size_t free_a_occupied_b = 0;   ///< known in both: free in a, occupied in b
  size_t occupied_a_free_b = 0;   ///< ... and the other way round
  size_t occupied_a = 0, occupied_b = 0;
  size_t occupied_both = 0;       ///< the same cell occupied in both
  size_t occupied_a_matched = 0;  ///< occupied in a, with an occupied cell of b within tolerance
  size_t occupied_b_matched = 0;  ///< ... and the other way round

  double class_agreement() const { return known_both ? double(same_class) / known_both : 0.0; }
  /// Occupied cells in a near an occupied cell of b (a's precision if b is the truth).
  double precision() const { return occupied_a ? double(occupied_a_matched) / occupied_a : 0.0; }
  /// Occupied cells in b near an occupied cell of a (a's recall if b is the truth).
  double recall() const { return occupied_b ? double(occupied_b_matched) / occupied_b : 0.0; }
  double occupied_iou() const {
    const size_t u = occupied_a + occupied_b - occupied_both;
    return u ? double(occupied_both) / u : 0.0;
  }
};

/// Throws std::invalid_argument if the resolutions differ.
MapAgreement compare_maps(const VoxelMap& a, const VoxelMap& b, int tolerance_cells = 1);

}  // namespace kestrel::mapper
