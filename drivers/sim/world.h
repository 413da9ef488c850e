#pragma once
// A synthetic world: textured planar surfaces, solid boxes, lights, and the queries the
// planner and the flights need (free space, clearance, segments, rays).
//
// A World is built once (WorldBuilder::build) and is immutable afterwards, so every const
// method is thread-safe. Building generates the textures (deterministic from the world's
// seed), the light maps and the collision index. Coordinates: world frame, z up, metres.

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sim/appearance.h"
#include "drivers/sim/collision.h"
#include "drivers/sim/materials.h"
#include "drivers/sim/surface.h"

namespace kestrel::sim {

/// A point light; irradiance falls off as power * cos / (d^2 + r0^2) (a soft source of about
/// r0 = 0.5 m). Powers are relative: the world's mean direct irradiance is normalised to one.
struct Light {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double power = 1.0;
};

/// Where the vehicle may be in a world extruded from a 2D map: the map's free cells.
struct FreeMask {
  cv::Mat free;  ///< CV_8UC1, non-zero = free
  Eigen::Affine2d T_pixel_world = Eigen::Affine2d::Identity();  ///< (x, y) -> (col, row)
  bool contains(const Eigen::Vector3d& p) const;
};

/// What of a world to build: everything, or its geometry alone (surfaces, boxes, bounds,
/// start, lights, collision queries) for what never renders it (a file's check, fuzzing):
/// textures and light maps are most of the time a world takes to build.
enum class WorldParts { kAll, kGeometry };

class World {
 public:
  /// False for a world built with WorldParts::kGeometry: look(), wear_texture() and
  /// feature_density() must not be called on it.
  bool has_appearance() const { return wear_ != nullptr; }
  const std::string& name() const { return name_; }
  /// The file or map the world was read from ("" if built in code).
  const std::string& source() const { return source_; }
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  /// Default take-off pose (x, y, z, yaw) for the flights.
  const Eigen::Vector4d& start() const { return start_; }
  const std::vector<MaterialSpec>& materials() const { return materials_; }
  const std::vector<Surface>& surfaces() const { return surfaces_; }
  const std::vector<Box>& boxes() const { return boxes_; }
  const std::vector<Light>& lights() const { return lights_; }
  const FreeMask* free_mask() const { return free_mask_ ? &*free_mask_ : nullptr; }

  /// Texture placement and light map of a surface (what the renderer draws).
  const SurfaceLook& look(int surface) const { return looks_[surface]; }
  /// The shared aperiodic wear texture that keeps tiled materials from repeating exactly.
  const MipTexture& wear_texture() const { return *wear_; }
  /// FAST corners (threshold 20) per square metre of a surface seen face-on from 2 m under
  /// nominal light: the texture density a feature-based sensor model should assume.
  double feature_density(int surface) const { return looks_[surface].features_per_m2; }

  /// Within the bounds and, for map worlds, on a free cell of the map.
  bool inside(const Eigen::Vector3d& p) const;
  /// Distance to the nearest obstacle (capped at `cap`); 0 inside a box.
  double clearance(const Eigen::Vector3d& p, double cap = 10.0) const { return index_.clearance(p, cap); }
  /// A sphere of `radius` at p is inside and touches nothing.
  bool is_free(const Eigen::Vector3d& p, double radius) const;
  /// The capsule of `radius` around [a, b] is inside (at its ends) and touches nothing.
  bool segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const;
  /// First surface along a ray (unit direction), within max_distance.
  std::optional<RayHit> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_distance) const {
    return index_.raycast(origin, direction, max_distance);
  }

 private:
  friend class WorldBuilder;
  World() = default;

  std::string name_;
  std::string source_;
  Eigen::AlignedBox3d bounds_;
  Eigen::Vector4d start_ = Eigen::Vector4d::Zero();
  std::vector<MaterialSpec> materials_;
  std::vector<Surface> surfaces_;
  std::vector<Box> boxes_;
  std::vector<Light> lights_;
  std::optional<FreeMask> free_mask_;
  std::vector<SurfaceLook> looks_;
  std::shared_ptr<const MipTexture> wear_;
  CollisionIndex index_;
};

}  // namespace kestrel::sim
