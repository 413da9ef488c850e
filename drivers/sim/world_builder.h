#pragma once
// Assembles a World from walls, floors, boxes, materials and lights, then builds it:
// textures, light maps, collision index and feature densities.
//
// Conventions: a wall from a to b (x, y) is seen from its left (so a counter-clockwise room
// outline faces inwards), with texture t pointing up; floors are seen from above, ceilings
// from below. The builder trusts its caller: parsers validate and report bad input with file
// and line before calling it, and the builder throws std::invalid_argument for values that
// cannot describe geometry at all.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "drivers/sim/lighting.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {

class WorldBuilder {
 public:
  explicit WorldBuilder(std::string name);

  void set_name(std::string name) { name_ = std::move(name); }
  void set_source(std::string source) { source_ = std::move(source); }
  /// Seed of the world's appearance (textures, texture placement, light-map variation).
  void set_seed(uint64_t seed) { seed_ = seed; }
  void set_bounds(const Eigen::AlignedBox3d& bounds) { bounds_ = bounds; }
  void set_start(const Eigen::Vector4d& start) { start_ = start; }
  void set_lighting(const LightingOptions& lighting) { lighting_ = lighting; }
  void set_free_mask(FreeMask mask) { free_mask_ = std::move(mask); }

  /// Adds a material and returns its index; names must be unique.
  int add_material(const MaterialSpec& spec);
  /// Index of the material called `name`, or -1.
  int material_index(const std::string& name) const;

  int add_floor(int material, const Eigen::AlignedBox2d& area, double z, double texture);
  int add_ceiling(int material, const Eigen::AlignedBox2d& area, double z, double texture);
  /// A one-sided vertical rectangle from a to b between heights z0 < z1, seen from the left.
  int add_wall(int material, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1,
               double texture, SurfaceKind kind = SurfaceKind::kWall);
  /// A solid box with its six outward faces; returns the box index.
  int add_box(int material, const Eigen::Isometry3d& T_world_box, const Eigen::Vector3d& half_extent,
              double texture);
  /// A wall of `thickness` centred on the segment a-b, as a solid box.
  int add_slab(int material, const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1,
               double thickness, double texture);
  void add_light(const Light& light) { lights_.push_back(light); }

  size_t surface_count() const { return surfaces_.size(); }
  const std::vector<Surface>& surfaces() const { return surfaces_; }

  /// Generates the world's `parts` (by default everything) and returns it; the builder is
  /// left empty.
  World build(WorldParts parts = WorldParts::kAll);

 private:
  // Textures, light maps and feature densities: most of a build's time.
  void add_appearance(World& w) const;
  int add_surface(Surface s, SurfaceKind kind, int material, double texture);
  void check_material(int material) const;

  std::string name_;
  std::string source_;
  uint64_t seed_ = 1;
  std::optional<Eigen::AlignedBox3d> bounds_;
  std::optional<Eigen::Vector4d> start_;
  LightingOptions lighting_;
  std::optional<FreeMask> free_mask_;
  std::vector<MaterialSpec> materials_;
  std::vector<Surface> surfaces_;
  std::vector<Box> boxes_;
  std::vector<Light> lights_;
};

}  // namespace kestrel::sim
