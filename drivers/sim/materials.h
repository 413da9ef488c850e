#pragma once
// Materials: procedural surface appearance, generated deterministically from a seed.
//
// A material names a pattern (brick, wood, carpet, poster, ...) and a few parameters. Its
// texture is generated once, in surface coordinates (metres along the surface's s and t axes),
// so a point of a wall looks the same from every view. A tiling material repeats with a period
// of `period_m()`; a fitted material (`fit`, e.g. posters) is stretched once over each surface
// that uses it, and each such surface gets its own, different instance.
//
// Patterns are built from periodic fractal noise (noise.h) at several octaves plus structure
// (mortar joints, planks, tiles, book spines, printed shapes), so that image statistics are
// natural-image-like and corners appear at several scales.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "drivers/sim/texture.h"

namespace kestrel::sim {

struct MaterialSpec {
  std::string name;     ///< the world file's name for it
  std::string pattern;  ///< one of pattern_names()
  Eigen::Vector3d color = Eigen::Vector3d(0.7, 0.7, 0.7);  ///< base colour, R, G, B in [0, 1]
  double scale = 1.0;     ///< multiplies the size of the pattern's features (and its period)
  double contrast = 1.0;  ///< multiplies the amplitude of the pattern's variations
  bool fit = false;       ///< stretch one unique instance over each surface instead of tiling
};

/// The patterns a material can use, with a one-line description each.
struct PatternInfo {
  const char* name;
  const char* description;
};
const std::vector<PatternInfo>& pattern_catalogue();
bool is_pattern(const std::string& name);

/// Texture side in texels for a pattern (a power of two).
int pattern_texture_size(const std::string& pattern);
/// The tile period of a tiling material, metres (ignored for fitted materials).
double pattern_period_m(const MaterialSpec& spec);

/// Generates the texture of `spec`; `seed` selects the instance (material or surface).
std::shared_ptr<const MipTexture> make_texture(const MaterialSpec& spec, uint64_t seed);

}  // namespace kestrel::sim
