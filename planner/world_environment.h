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
#include <vector>

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
  /// The same answer as line_of_sight_by_raycast, bit for bit (test
  /// FastLineOfSightEqualsTheSimsRaycast), from the obstacles near the segment only.
  bool line_of_sight(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const override;
  /// The definition: the sim's ray cast, which gathers, sorts and tests every obstacle whose
  /// 1 m cells meet the segment's bounding box.
  bool line_of_sight_by_raycast(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  /// Many rays from a: the obstacles near a are gathered once, then each ray tests those
  /// whose box meets its own (same answers, test FastLineOfSightEqualsTheSimsRaycast).
  void lines_of_sight(const Eigen::Vector3d& a, const std::vector<Eigen::Vector3d>& targets,
                      std::vector<char>& out) const override;

  const sim::World& world() const { return world_; }

  /// Draws and installs the features (see the file comment); returns how many.
  size_t place_features(const WorldFeatureOptions& options);

 private:
  const sim::World& world_;

  // The sim's obstacles (rectangles that are no box face, and boxes) with the 1 m cell range
  // its CollisionIndex files each under, so that a hit counts only where the sim's ray cast
  // would have tested that obstacle; and a finer grid of them for walking the segment.
  struct Obstacle {
    bool is_box = false;
    int index = -1;            ///< in world().surfaces() or world().boxes()
    bool global = false;       ///< the sim tests it for every ray (floors, ceilings)
    int ix0 = 0, ix1 = 0, iy0 = 0, iy1 = 0;  ///< the sim's cell range
    Eigen::Isometry3d T_box_world = Eigen::Isometry3d::Identity();
    Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();  ///< its box, grown by the slack
  };
  std::vector<Obstacle> obstacles_;
  std::vector<int> global_;      ///< obstacles the sim tests always
  double sim_origin_x_ = 0.0, sim_origin_y_ = 0.0;
  int sim_nx_ = 0, sim_ny_ = 0;
  double fine_cell_m_ = 0.5;
  double fine_origin_x_ = 0.0, fine_origin_y_ = 0.0;
  int fine_nx_ = 0, fine_ny_ = 0;
  std::vector<int> fine_start_, fine_items_;  ///< CSR: cell c holds fine_items_[fine_start_[c] .. fine_start_[c + 1])

  // Whether the sim's ray cast from a to end files obstacle o among those it tests.
  bool sim_tests(const Obstacle& o, const Eigen::Vector3d& a, const Eigen::Vector3d& end) const;
  bool hits(const Obstacle& o, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_distance) const;
};

}  // namespace kestrel::planner
