#include "metrics/association.h"

#include <stdexcept>

namespace kestrel::metrics {

Association associate(const std::vector<int64_t>& frame_utimes, const Trajectory& est,
                      const Trajectory& gt, const EvalOptions& options) {
  Association a;
  a.frames.reserve(frame_utimes.size());
  for (size_t i = 0; i < frame_utimes.size(); ++i) {
    if (i > 0 && frame_utimes[i] <= frame_utimes[i - 1])
      throw std::invalid_argument("associate: frame times are not strictly increasing");
    FramePoses f;
    f.utime = frame_utimes[i];
    f.T_world_est = est.at(f.utime, options.est_max_gap_us);
    f.T_world_gt = gt.at(f.utime, options.gt_max_gap_us);
    if (!f.T_world_est) ++a.no_estimate;
    if (!f.T_world_gt) {
      if (gt.empty() || f.utime < gt.poses().front().utime) {
        f.gt_missing = GtMissing::kBeforeStart;
        ++a.no_gt_before_start;
      } else if (f.utime > gt.poses().back().utime) {
        f.gt_missing = GtMissing::kAfterEnd;
        ++a.no_gt_after_end;
      } else {
        f.gt_missing = GtMissing::kInGap;
        ++a.no_gt_in_gap;
      }
    }
    if (f.scored()) ++a.scored;
    a.frames.push_back(std::move(f));
  }
  return a;
}

}  // namespace kestrel::metrics
