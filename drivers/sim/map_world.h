#pragma once
// A 3D world extruded from a 2D occupancy map (e.g. the MIT Stata basement).
//
// The map's free space is cleaned (thin spurs of free space, as left by laser rays through
// doors, are opened away; only the largest connected free region is kept), its boundary is
// traced and simplified into wall segments (collinear runs merged within `simplify_m`), and
// each boundary segment becomes a vertical wall facing the free side, `wall_height` tall.
// Walls get materials and texture densities at random from the seed: some are blank, long
// ones carry posters, boards and doors, like the paper's Section 3 environment. Ceiling
// lights are spread along the free space. The result is deterministic for a given map and seed.

#include <cstdint>

#include "drivers/sim/occupancy_map.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {

struct MapWorldOptions {
  double wall_height_m = 3.0;
  double simplify_m = 0.1;       ///< tolerance when merging boundary runs into straight walls
  double min_passage_m = 0.3;    ///< free space narrower than this is treated as solid
  double min_obstacle_m2 = 0.1;  ///< smaller specks of non-free space are ignored
  double max_wall_piece_m = 8.0; ///< longer walls are split into pieces with their own look
  double blank_share = 0.25;     ///< share of wall pieces that are featureless
  double light_spacing_m = 4.0;
  uint64_t seed = 1;             ///< appearance seed (textures, wall looks, posters)
};

/// Builds the world; `name` becomes World::name(). Throws InputError naming the map if it
/// has no usable free space.
World world_from_map(const OccupancyMap& map, const std::string& name, const MapWorldOptions& options = {});

}  // namespace kestrel::sim
