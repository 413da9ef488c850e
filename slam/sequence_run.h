#pragma once
// VO + SLAM in one process over decoded frames (the offline `kestrel slam --tum`, the data
// tests): each frame through the visual odometry, the chained odometry pose to SLAM, and at
// the end every frame's pose both as the odometry had it and as the optimised graph puts it.

#include <memory>
#include <vector>

#include "common/trajectory.h"
#include "slam/backend/slam.h"
#include "vo/options.h"

namespace kestrel::slam {

struct SlamRun {
  Trajectory vo;                   ///< T_world_camera by chained odometry alone
  Trajectory slam;                 ///< the same frames placed by the optimised keyframe graph
  int keyframes = 0;
  int loop_closures = 0;
  int candidates_verified = 0;
  std::vector<double> keyframe_ms; ///< SLAM time per keyframe (features, loop search, optimisation)
};

SlamRun run_slam_sequence(const std::vector<RgbdFrame>& frames, const vo::VoOptions& vo_options,
                          const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary);

}  // namespace kestrel::slam
