#pragma once
// Which stored views to let go first when a memory budget is exceeded: views (keyframes) are
// binned by where the camera was (cells of cell_m) and where it looked (sectors of sector_deg
// of the optical axis' azimuth and elevation), and the oldest view of the fullest bin goes
// first (among equally full bins, the oldest view). So places seen from many nearby, similar
// viewpoints are thinned first, and a place seen once keeps its only view while any place has
// more. The mapper's stored scans and SLAM's matchable keyframes share it.
//
// Invariants: an id is in at most one bin; "oldest" is the order of insertion into the bin (a
// view that moves to another bin is the newest there); ids grow with time.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <tuple>
#include <vector>

namespace kestrel {

class ViewBins {
 public:
  /// Throws std::invalid_argument for a cell that is not finite > 0 or a sector outside (0, 180].
  ViewBins(double cell_m, double sector_deg);

  /// Adds `id` seen from T_world_camera (optical frame: z forward); an id already there moves.
  void insert(int64_t id, const Eigen::Isometry3d& T_world_camera);
  /// Forgets `id` (nothing if absent).
  void erase(int64_t id);
  /// The oldest id of the fullest bin, other than `keep`; none when no other id is binned.
  std::optional<int64_t> first_to_thin(std::optional<int64_t> keep = std::nullopt) const;

  size_t size() const { return bin_of_id_.size(); }
  void clear();

 private:
  using Bin = std::tuple<int, int, int, int, int>;  // position cell, axis azimuth and elevation
  Bin bin_of(const Eigen::Isometry3d& T) const;

  double cell_m_;
  double sector_rad_;
  std::map<int64_t, Bin> bin_of_id_;
  std::map<Bin, std::vector<int64_t>> bins_;  // ids in insertion order
};

}  // namespace kestrel
