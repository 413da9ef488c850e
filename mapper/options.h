#pragma once
// Options of the occupancy mapper, each field with its default and unit.
//
// The sensor model defaults are OctoMap's own (hit 0.7, miss 0.4, clamping 0.1192 / 0.971,
// threshold 0.5), so that a map built here and one built by OcTree::insertPointCloud from the
// same rays agree cell for cell. validate() throws std::invalid_argument naming the field.

#include <cstdint>

namespace kestrel::mapper {

/// The log-odds occupancy model of every cell.
struct MapOptions {
  double resolution_m = 0.10;       ///< leaf size
  double prob_hit = 0.7;            ///< P(occupied | ray ends in the cell)
  double prob_miss = 0.4;           ///< P(occupied | ray passes through the cell)
  double clamp_min = 0.1192;        ///< probabilities are clamped to [clamp_min, clamp_max]
  double clamp_max = 0.971;
  double occupancy_threshold = 0.5; ///< occupied when P >= this (OctoMap's rule)
  /// Forgetting, so that moved obstacles clear: every cell's log-odds decays towards 0 with this
  /// half-life (sensor time), and a cell whose |log-odds| falls below `forget_below` becomes
  /// unknown again. 0 = off (OctoMap's behaviour, and the default).
  double decay_half_life_s = 0.0;
  double decay_period_s = 0.5;      ///< decay is applied in steps of at least this much time
  double forget_below = 0.2;        ///< log-odds magnitude below which a decayed cell is dropped

  void validate() const;
};

/// How a depth image becomes rays.
struct ScanOptions {
  /// Depth is decimated by picking every `stride`-th pixel in both directions (centred), so 5
  /// turns 640x480 into 128x96 (the paper's insertion size); 1 keeps every pixel.
  int stride = 5;
  /// Readings farther than this are not hits: their ray is cut at this range and only clears
  /// free space (OctoMap's maxrange semantics).
  double max_range_m = 4.0;
  /// Readings nearer than this are ignored (the Kinect reports nothing reliable below ~0.4 m).
  double min_range_m = 0.0;
  /// Endpoint discretisation, OctoMap's insertPointCloud(..., discretize = true): the readings
  /// are reduced to one per cell and replaced by that cell's centre before the rays are cast,
  /// so fewer rays, and the map is OctoMap's discretised map rather than its per-ray one
  /// (scan_integrator.h).
  bool discretize = false;

  void validate() const;
};

}  // namespace kestrel::mapper
