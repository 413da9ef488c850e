#pragma once
// A SLAM map: what one flight leaves for the next (issue 41). The keyframes with their
// features (what place recognition and geometric verification match against), the pose graph
// of their optimised poses, the loop gate's model of each edge, and the vocabulary that
// indexes the keyframes. Slam::map() takes it, a Slam constructed from it goes on from it, and
// slam/map/map_file.h keeps it on disk.
//
// Sessions: each flight that added keyframes is a session, numbered from 0. A keyframe keeps
// the session that made it, because time means nothing between sessions (two flights may
// both start at utime 0): a loop candidate must be min_age_s older only within its session.
//
// Invariants (check_map() enforces them): keyframe k has id k and is vertex k of the graph;
// graph.ids[k] == k; every pose is a finite rigid transform; gate_information has one entry
// per edge; a keyframe's session is in [0, sessions); a thinned keyframe has no features and
// the others have parallel keypoints, 32-byte descriptor rows and points; the vocabulary is
// set (it may be empty: an online vocabulary never trained, then the keyframes rebuild one).

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "sensors/sensor_profile.h"
#include "slam/place/frame_features.h"
#include "slam/place/vocabulary.h"
#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam {

/// How a frame's odometry pose relates to the previous frame's.
enum class OdometryLink {
  kContinuous,  ///< the visual odometry carried on: the pose follows from the previous one
  kBridged,     ///< the VO restarted and the state estimator (IMU) bridged the gap: related, less certain
  kBroken,      ///< the VO restarted and nothing relates the poses
};

struct Keyframe {
  int64_t id = 0;                 ///< = its index
  int64_t utime = 0;
  int session = 0;                ///< the flight that made it (see the top)
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();  ///< in its session's odometry frame
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// The camera at the depth image's time, in the camera at utime's frame (the timing's
  /// motion over the depth offset; identity when the motion is unknown).
  Eigen::Isometry3d T_camera_depth = Eigen::Isometry3d::Identity();
  /// How its odometry pose relates to the previous keyframe's (the first's: kContinuous).
  OdometryLink link = OdometryLink::kContinuous;
  sensors::SensorProfile sensor;  ///< its camera's profile (its loops' noise); empty: none
  FrameFeatures features;         ///< empty once thinned (KeyframeMemoryOptions)
  bool thinned = false;           ///< its features went to keep within the memory budget
};

/// Bytes a keyframe's features take (what KeyframeMemoryOptions::max_megabytes bounds).
size_t memory_of(const FrameFeatures& features);

struct SlamMap {
  std::vector<Keyframe> keyframes;
  PoseGraph3d graph;                    ///< vertex k: keyframe k's optimised T_world_camera
  std::vector<Matrix6d> gate_information;  ///< per edge: the loop-consistency gate's model
  std::shared_ptr<const Vocabulary> vocabulary;
  int sessions = 0;                     ///< flights that made it
  /// The graph's revision when it was taken (Slam::revision()): a Slam going on from the map
  /// continues from it, so the published revisions never go back (slam_messages.h).
  int64_t revision = 0;
};

/// Throws InputError naming `what` and the first broken invariant (see the top).
void check_map(const SlamMap& map, const std::string& what);

}  // namespace kestrel::slam
