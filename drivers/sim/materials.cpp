#include "drivers/sim/materials.h"

#include <stdexcept>

#include "drivers/sim/patterns.h"

namespace kestrel::sim {
namespace {

using Generator = cv::Mat (*)(const MaterialSpec&, int, Rng&);

struct Pattern {
  PatternInfo info;
  Generator generate;
  int size;         // texels per side
  double period_m;  // tile period at scale 1 (tiling use)
};

// Periods are chosen so that the finest texels are about 2 mm: finer than a Kinect pixel at
// 0.5 m, the closest the camera sees.
const std::vector<Pattern>& pattern_table() {
  static const std::vector<Pattern> table = {
      {{"plaster", "painted wall: faint undulation, nearly featureless"}, patterns::plaster, 1024, 2.048},
      {{"concrete", "blotchy concrete with pores and stains"}, patterns::concrete, 1024, 2.048},
      {{"carpet", "loop-pile carpet: fine fibres, mottling, flecks"}, patterns::carpet, 1024, 2.048},
      {{"fabric", "woven fabric (partitions, seats)"}, patterns::fabric, 512, 1.024},
      {{"screen", "dark glossy panel (monitors); Kinect depth drops out"}, patterns::screen, 256, 1.024},
      {{"brick", "running-bond brick with mortar joints"}, patterns::brick, 1024, 2.025},
      {{"wood", "wooden planks with grain and joints"}, patterns::wood, 1024, 2.048},
      {{"floor_tiles", "30 cm floor tiles with grout and speckle"}, patterns::floor_tiles, 1024, 2.4},
      {{"ceiling_tiles", "60 cm fissured ceiling tiles on a metal grid"}, patterns::ceiling_tiles, 1024, 2.4},
      {{"books", "book shelves: spines of random size and colour"}, patterns::books, 1024, 2.048},
      {{"poster", "printed poster: photographs, headings, text (use with fit)"}, patterns::poster, 512, 1.0},
      {{"whiteboard", "whiteboard with a few marker strokes (use with fit)"}, patterns::whiteboard, 512, 1.5},
  };
  return table;
}

const Pattern& find(const std::string& name) {
  for (const Pattern& p : pattern_table())
    if (name == p.info.name) return p;
  throw std::invalid_argument("unknown material pattern '" + name + "'");
}

}  // namespace

const std::vector<PatternInfo>& pattern_catalogue() {
  static const std::vector<PatternInfo> infos = [] {
    std::vector<PatternInfo> v;
    for (const Pattern& p : pattern_table()) v.push_back(p.info);
    return v;
  }();
  return infos;
}

bool is_pattern(const std::string& name) {
  for (const Pattern& p : pattern_table())
    if (name == p.info.name) return true;
  return false;
}

int pattern_texture_size(const std::string& pattern) { return find(pattern).size; }

double pattern_period_m(const MaterialSpec& spec) { return find(spec.pattern).period_m * spec.scale; }

std::shared_ptr<const MipTexture> make_texture(const MaterialSpec& spec, uint64_t seed) {
  const Pattern& p = find(spec.pattern);
  Rng rng(derive(seed, tag(spec.pattern)));
  return std::make_shared<const MipTexture>(p.generate(spec, p.size, rng));
}

}  // namespace kestrel::sim
