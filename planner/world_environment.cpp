// WorldEnvironment: the sim's world behind the planner's Environment interface.
#include "planner/world_environment.h"

#include <random>
#include <stdexcept>

#include "planner/types.h"

namespace kestrel::planner {

WorldEnvironment::WorldEnvironment(const sim::World& world) : world_(world) {}

bool WorldEnvironment::line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  // The last millimetre is the target's own surface: a feature on a wall sees its viewer.
  constexpr double kTargetMargin_m = 1e-3;
  if (length <= kTargetMargin_m) return true;
  return !world_.raycast(a, d / length, length - kTargetMargin_m).has_value();
}

size_t WorldEnvironment::place_features(const WorldFeatureOptions& options) {
  if (!(options.mean_density_per_m2 >= 0.0)) throw std::invalid_argument("place_features: density must be >= 0");
  const auto& surfaces = world_.surfaces();
  double area = 0.0, weighted = 0.0;
  for (const sim::Surface& s : surfaces)
    if (s.is_vertical()) {
      area += s.area();
      weighted += world_.feature_density(s.id) * s.area();
    }
  std::vector<Feature> features;
  if (weighted > 0.0) {
    const double scale = options.mean_density_per_m2 * area / weighted;
    Rng rng(options.seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const sim::Surface& s : surfaces) {
      if (!s.is_vertical()) continue;
      const double expected = scale * world_.feature_density(s.id) * s.area();
      if (!(expected > 0.0)) continue;
      std::poisson_distribution<int> count(expected);
      for (int k = count(rng); k > 0; --k) {
        Feature f;
        f.position = s.point(u(rng) * s.width, u(rng) * s.height);
        f.normal = s.normal;
        features.push_back(f);
      }
    }
  }
  set_features(std::move(features));
  return this->features().size();
}

}  // namespace kestrel::planner
