#pragma once
// Association: every frame of a reference frame list paired with its estimated pose and its
// ground-truth pose, each looked up with Trajectory::at (interpolated only when the samples
// on both sides lie within the configured gap).
//
// A frame is *scored* when it has both poses. A frame without an estimate is a failure of the
// estimator (it counts toward the gross failures); a frame without ground truth cannot be
// judged and is left out of every metric, with the reason counted.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <vector>

#include "common/trajectory.h"
#include "metrics/options.h"

namespace kestrel::metrics {

/// Why a frame has no ground truth.
enum class GtMissing { kNone, kBeforeStart, kAfterEnd, kInGap };

struct FramePoses {
  int64_t utime = 0;
  std::optional<Eigen::Isometry3d> T_world_est;  ///< in the estimate's world
  std::optional<Eigen::Isometry3d> T_world_gt;   ///< in the ground truth's world
  GtMissing gt_missing = GtMissing::kNone;
  bool scored() const { return T_world_est.has_value() && T_world_gt.has_value(); }
};

struct Association {
  std::vector<FramePoses> frames;  ///< in the order of the frame list (increasing utime)
  size_t scored = 0;
  size_t no_estimate = 0;
  size_t no_gt_before_start = 0;  ///< frame before the first ground-truth sample
  size_t no_gt_after_end = 0;     ///< frame after the last ground-truth sample
  size_t no_gt_in_gap = 0;        ///< no sample within the gap on one side or both
  size_t no_ground_truth() const { return no_gt_before_start + no_gt_after_end + no_gt_in_gap; }
};

/// Associates each of `frame_utimes` (strictly increasing; std::invalid_argument otherwise).
Association associate(const std::vector<int64_t>& frame_utimes, const Trajectory& est,
                      const Trajectory& gt, const EvalOptions& options);

}  // namespace kestrel::metrics
