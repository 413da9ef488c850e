// ConfigurationSpace: validity and uniform sampling of (x, y, z, yaw).
#include "planner/configuration_space.h"

#include "common/numbers.h"

#include <stdexcept>

namespace kestrel::planner {

ConfigurationSpace::ConfigurationSpace(const Environment& env, SpaceOptions options)
    : env_(env), options_(options) {
  if (!(options.radius_m > 0.0)) throw std::invalid_argument("ConfigurationSpace: radius must be > 0");
  if (!(options.z_max_m >= options.z_min_m))
    throw std::invalid_argument("ConfigurationSpace: z_max must be >= z_min");
  const Eigen::AlignedBox3d b = env.bounds();
  box_ = Eigen::AlignedBox3d(Eigen::Vector3d(b.min().x(), b.min().y(), options.z_min_m),
                             Eigen::Vector3d(b.max().x(), b.max().y(), options.z_max_m));
}

bool ConfigurationSpace::is_valid(const Config& q) const {
  return q.allFinite() && env_.is_free(position(q), options_.radius_m);
}

bool ConfigurationSpace::motion_valid(const Config& a, const Config& b) const {
  return a.allFinite() && b.allFinite() && env_.segment_is_free(position(a), position(b), options_.radius_m);
}

Config ConfigurationSpace::uniform(Rng& rng) const {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Config q;
  for (int i = 0; i < 3; ++i) q[i] = box_.min()[i] + u01(rng) * (box_.max()[i] - box_.min()[i]);
  q[3] = wrap_angle((2.0 * u01(rng) - 1.0) * kPi);
  return q;
}

Config ConfigurationSpace::clamp_band(Config q) const {
  q[2] = std::clamp(q[2], box_.min().z(), box_.max().z());
  q[3] = wrap_angle(q[3]);
  return q;
}

}  // namespace kestrel::planner
