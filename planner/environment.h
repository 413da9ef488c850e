#pragma once
// What the planner needs from the world, whatever it came from (a synthetic world, a 2D map
// extruded in height, an OctoMap): free-space queries for a vehicle of a given radius, line of
// sight for the sensor models, and the point features the feature sensors observe.
//
// Implementations are immutable once built, so every query is const and thread-safe.

#include <Eigen/Geometry>
#include <vector>

namespace kestrel::planner {

/// A point landmark on a surface; it is seen only from the side its normal points to.
struct Feature {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

class Environment {
 public:
  virtual ~Environment() = default;
  /// Axis-aligned box the vehicle's centre must stay in.
  virtual Eigen::AlignedBox3d bounds() const = 0;
  /// A sphere of `radius` at p lies in known free space.
  virtual bool is_free(const Eigen::Vector3d& p, double radius) const = 0;
  /// The capsule of `radius` around [a, b] lies in known free space.
  virtual bool segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const = 0;
  /// Nothing opaque between a and b (b itself may lie on a surface).
  virtual bool line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const = 0;
  /// line_of_sight(a, b) for every b of `targets`: out[i] = 1 when seen, else 0. An
  /// environment may answer many rays from one point faster than one by one, never differently.
  virtual void lines_of_sight(const Eigen::Vector3d& a, const std::vector<Eigen::Vector3d>& targets,
                              std::vector<char>& out) const {
    out.resize(targets.size());
    for (size_t i = 0; i < targets.size(); ++i) out[i] = line_of_sight(a, targets[i]) ? 1 : 0;
  }
  /// Landmarks for the feature sensors (may be empty).
  const std::vector<Feature>& features() const { return features_; }
  void set_features(std::vector<Feature> features) { features_ = std::move(features); }

 private:
  std::vector<Feature> features_;
};

}  // namespace kestrel::planner
