#pragma once
// VO + SLAM in one process over decoded frames (the offline `kestrel slam --tum`, the data
// tests): each frame through the visual odometry, the chained odometry pose to SLAM, and at
// the end every frame's pose both as the odometry had it and as the optimised graph puts it.
// Keyframes' features get the odometry's timing correction (place/frame_features.h): the
// camera's timing is that of the VO options of its sensor profile (vo::tum_sensor() for a TUM
// folder), the motion the odometry's from the previous frame to the keyframe.

#include <functional>
#include <memory>
#include <vector>

#include "common/trajectory.h"
#include "slam/backend/slam.h"
#include "vo/odometry.h"
#include "vo/options.h"

namespace kestrel::slam {

/// An accepted loop closure: the graph edge between two keyframes, by their utimes, with its
/// measured relative pose T_from_to (camera frames).
struct LoopEdge {
  int64_t from_utime = 0;
  int64_t to_utime = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
};

struct SlamRun {
  std::vector<vo::VoResult> odometry;  ///< the VO's result for each frame, in order (vo::require_usable)
  Trajectory vo;                   ///< T_world_camera by chained odometry alone
  Trajectory slam;                 ///< the same frames placed by the optimised keyframe graph
  int keyframes = 0;
  int loop_closures = 0;
  int reanchors = 0;               ///< frames located in a covering keyframe instead of becoming one
  Slam::CoverageMisses coverage_misses;  ///< why frames over covered ground became keyframes, or were carried
  int candidates_verified = 0;
  int inconsistent_loops = 0;      ///< verified loops refused as disagreeing with the odometry
  std::vector<double> keyframe_ms; ///< SLAM time per keyframe (features, loop search, optimisation)
  std::vector<LoopEdge> loops;     ///< every accepted loop closure, in the order found
  /// Started from a saved map: where the camera was placed in it (none: never). Frames before
  /// that have no SLAM pose (`slam` starts there); `slam` is in the map's world.
  std::optional<Relocalisation> relocalisation;
  SlamMap map;                     ///< the map at the end (what --save-map writes)
};

/// A loop closure's error against the ground truth: E = (T_from_to true)^-1 T_from_to measured.
struct LoopError {
  LoopEdge edge;
  bool has_truth = false;  ///< the ground truth covers both keyframes' times
  double translation_m = 0.0;
  double rotation_rad = 0.0;
};

/// What the optimised graph says of the odometry at one reference (a keyframe, or a frame
/// re-anchored on one: Slam::reference()): T_world_odom, the pose the graph gives it times the
/// inverse of the odometry's.
struct KeyframeCorrection {
  int64_t utime = 0;
  Eigen::Isometry3d T_world_odom = Eigen::Isometry3d::Identity();
  bool continues_previous = false;  ///< one odometry segment from the previous reference to this one
};

/// A frame's pose by the graph: `T_odom_camera` after `keyframes[newest]` (the newest reference
/// at its time, at or before `utime`), corrected by the references' T_world_odom interpolated by
/// time between that reference and the next, when the next continues its odometry segment;
/// else by the reference's own. The odometry's error grows from each reference, so a correction
/// is spread along the segment instead of arriving as a jump at the next reference.
Eigen::Isometry3d place_frame(const std::vector<KeyframeCorrection>& keyframes, size_t newest, int64_t utime,
                              const Eigen::Isometry3d& T_odom_camera);

/// The error of each of `run`'s loop closures against `ground_truth` (T_world_camera, as
/// TUM's groundtruth.txt; interpolated within 0.1 s).
std::vector<LoopError> loop_errors(const SlamRun& run, const Trajectory& ground_truth);

/// `sensor`: the camera's profile, which sets the odometry's options (vo::with_sensor() of
/// `vo_options`; the keyframes' timing) and the noise of SLAM's loops (Slam::add).
SlamRun run_slam_sequence(const std::vector<RgbdFrame>& frames, const sensors::SensorProfile& sensor,
                          const vo::VoOptions& vo_options, const SlamOptions& options,
                          std::shared_ptr<const Vocabulary> vocabulary);

/// The same over `count` frames decoded one at a time by `frame_at(i)` (a long sequence need
/// not fit in memory: 1.5 MB a VGA frame). With `map`, SLAM goes on from that saved map
/// (Slam's constructor from a map: relocalisation first; `vocabulary` is then unused).
SlamRun run_slam_sequence(size_t count, const std::function<RgbdFrame(size_t)>& frame_at, const sensors::SensorProfile& sensor,
                          const vo::VoOptions& vo_options, const SlamOptions& options,
                          std::shared_ptr<const Vocabulary> vocabulary, std::shared_ptr<const SlamMap> map = nullptr);

}  // namespace kestrel::slam
