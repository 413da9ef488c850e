#pragma once
// The synthetic world of drivers/sim as a planner Environment: the sim's own collision
// queries (exact rectangles and boxes) and ray casts, so the planner flies the same `floor`
// and `stata` worlds the simulator renders.
//
// Features for the feature sensors are drawn on the world's vertical surfaces (walls, panels,
// sides of furniture), never on floor or ceiling. Each surface gets a density proportional to
// the texture density the sim reports for it (FAST corners per m², World::feature_density):
// blank plaster gets almost none, posters and brick many. The proportionality constant makes
// the area-weighted mean over all vertical surfaces equal to `mean_density_per_m2`, so the
// absolute level stays a parameter (the paper does not give one) while which walls are rich
// and which are blank comes from the world itself. Deterministic for a world and seed.

#include <cstdint>
#include <string>

#include "drivers/sim/world.h"
#include "planner/environment.h"

namespace kestrel::planner {

struct WorldFeatureOptions {
  double mean_density_per_m2 = 4.0;  ///< area-weighted mean over the vertical surfaces
  uint64_t seed = 1;
};

class WorldEnvironment : public Environment {
 public:
  /// Keeps a reference to `world`, which must outlive this.
  explicit WorldEnvironment(const sim::World& world);

  Eigen::AlignedBox3d bounds() const override { return world_.bounds(); }
  bool is_free(const Eigen::Vector3d& p, double radius) const override { return world_.is_free(p, radius); }
  bool segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const override {
    return world_.segment_is_free(a, b, radius);
  }
  /// No surface strictly between a and b (a feature lying on a surface at b is visible).
  bool line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const override;

  const sim::World& world() const { return world_; }

  /// Draws and installs the features (see the file comment); returns how many.
  size_t place_features(const WorldFeatureOptions& options);

 private:
  const sim::World& world_;
};

}  // namespace kestrel::planner
