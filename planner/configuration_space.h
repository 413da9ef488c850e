#pragma once
// The configuration space R^3 x S^1 (x, y, z, yaw) over an Environment: validity of a
// configuration and of the straight motion between two, for a spherical vehicle.
//
// Sampling covers the environment's x-y bounds and the flight band [z_min_m, z_max_m]
// (equal values fix the height, as in the paper's planar experiments); yaw is uniform.

#include "planner/environment.h"
#include "planner/types.h"

namespace kestrel::planner {

struct SpaceOptions {
  double radius_m = 0.3;   ///< vehicle radius (the paper's vehicle is about 70 cm across)
  double z_min_m = 1.0;    ///< flight band for sampling
  double z_max_m = 1.0;
};

class ConfigurationSpace {
 public:
  /// Throws std::invalid_argument for a non-positive radius or an empty band.
  ConfigurationSpace(const Environment& env, SpaceOptions options);

  const Environment& environment() const { return env_; }
  const SpaceOptions& options() const { return options_; }
  /// The box samples are drawn from (x, y from the environment, z from the band).
  const Eigen::AlignedBox3d& sample_box() const { return box_; }

  bool is_valid(const Config& q) const;
  bool motion_valid(const Config& a, const Config& b) const;
  /// A configuration uniform over the sample box and yaw (not necessarily valid).
  Config uniform(Rng& rng) const;
  /// Keeps q's position inside the sample box's band (z clamped); used by offset samplers.
  Config clamp_band(Config q) const;
  /// Distance used by the roadmap: Euclidean in position (yaw is free along edges).
  static double distance(const Config& a, const Config& b) { return (a.head<3>() - b.head<3>()).norm(); }

 private:
  const Environment& env_;
  SpaceOptions options_;
  Eigen::AlignedBox3d box_;
};

}  // namespace kestrel::planner
