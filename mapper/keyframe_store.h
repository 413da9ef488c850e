#pragma once
// The keyframes the map is built from, kept so that the map can be rebuilt when SLAM moves
// them (a loop closure), within a memory budget.
//
// A keyframe is stored as the decimated frame that was inserted (depth at insertion
// resolution, colour for the point cloud), so a rebuild inserts exactly the same rays again;
// at 128x96 that is about 61 kB a keyframe (0.5 GB holds about 8,500 of them).
//
// Policy when the budget is exceeded (common/geometry/view_bins.h): keyframes are binned by
// position (bin_size_m cells) and viewing direction (bin_angle_deg sectors of the optical axis);
// the oldest keyframe of the fullest bin is dropped. So places seen from many nearby, similar
// viewpoints are thinned first, and a place seen once keeps its only view. The newest keyframe
// is never dropped.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "common/geometry/view_bins.h"
#include "common/rgbd_frame.h"

namespace kestrel::mapper {

struct KeyframeOptions {
  double max_megabytes = 512.0;  ///< budget for the stored frames
  double bin_size_m = 0.5;       ///< thinning bins: position cell size
  double bin_angle_deg = 30.0;   ///< thinning bins: optical-axis sector size
  void validate() const;
};

struct StoredKeyframe {
  int64_t id = 0;
  int64_t utime = 0;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  RgbdFrame frame;  ///< as inserted (decimated)
  /// The depth image's camera in the camera at utime (a SLAM keyframe's timing; identity for
  /// frames placed at their depth time already). The depth goes in at T_world_depth().
  Eigen::Isometry3d T_camera_depth = Eigen::Isometry3d::Identity();
  /// When it was stored, counted by the store (KeyframeStore::add sets it; a replaced keyframe
  /// counts as stored anew).
  uint64_t stored_order = 0;
  Eigen::Isometry3d T_world_depth() const { return T_world_camera * T_camera_depth; }
  size_t bytes() const;
};

class KeyframeStore {
 public:
  explicit KeyframeStore(const KeyframeOptions& options = {});

  /// Adds a keyframe (replacing one with the same id), then drops keyframes by the policy above
  /// while over budget.
  void add(StoredKeyframe keyframe);
  /// Moves a keyframe; false if it is not stored.
  bool set_pose(int64_t id, const Eigen::Isometry3d& T_world_camera);
  const StoredKeyframe* find(int64_t id) const;
  bool contains(int64_t id) const { return keyframes_.count(id) != 0; }
  /// The largest id stored (none when empty).
  std::optional<int64_t> max_id() const {
    return keyframes_.empty() ? std::nullopt : std::optional<int64_t>(keyframes_.rbegin()->first);
  }
  /// Stored keyframes in the order they were stored: the order the live map took them in, and
  /// so the order a rebuild inserts them in and a journal's compaction writes them in. Not
  /// sensor time: two flights on one saved map may share sensor times (simulated ones all start
  /// at the same utime), and a keyframe SLAM places late (a joined session's) is stored after
  /// newer ones.
  std::vector<const StoredKeyframe*> in_stored_order() const;

  size_t size() const { return keyframes_.size(); }
  size_t bytes() const { return bytes_; }
  size_t dropped() const { return dropped_; }
  void clear();

 private:
  void drop_one(int64_t keep);

  KeyframeOptions options_;
  std::map<int64_t, StoredKeyframe> keyframes_;
  ViewBins bins_;
  size_t bytes_ = 0;
  size_t dropped_ = 0;
  uint64_t next_stored_order_ = 0;
};

}  // namespace kestrel::mapper
