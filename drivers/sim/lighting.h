#pragma once
// Light maps: the irradiance on every surface from the world's lights (cosine law, soft
// inverse-square falloff, hard shadows cast by every obstacle) plus ambient light, times a
// slow per-surface albedo variation (dirt, fading). Lighting is baked once per world, so it
// varies across a room but is the same from every view (Lambertian surfaces).

#include <vector>

#include "drivers/sim/appearance.h"
#include "drivers/sim/collision.h"
#include "drivers/sim/surface.h"

namespace kestrel::sim {

struct Light;

struct LightingOptions {
  double ambient = 0.35;        ///< share of the mean irradiance that is ambient (unshadowed)
  double cell_m = 0.2;          ///< light-map node spacing, metres (coarser on huge surfaces)
  int max_nodes = 40000;        ///< per surface
  double source_radius_m = 0.5; ///< softens the falloff near a light: 1 / (d^2 + r^2)
  double range_m = 9.0;         ///< lights farther than this do not reach a point
  double variation = 0.08;      ///< relative amplitude of the slow albedo variation
};

/// Fills looks[i].shade for every surface. The mean direct irradiance over the lit surfaces
/// is normalised to (1 - ambient), so a world's overall brightness does not depend on how
/// many lights it has; with no lights the irradiance is 1 everywhere.
void compute_shade_maps(std::vector<SurfaceLook>& looks, const std::vector<Surface>& surfaces,
                        const std::vector<Light>& lights, const CollisionIndex& index,
                        const LightingOptions& options, uint64_t seed);

}  // namespace kestrel::sim
