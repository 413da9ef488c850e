#pragma once
// The paper's frame-to-frame metrics (Bachrach et al. 2012, Table 1): the mean velocity
// error and the gross-failure rate.
//
// Velocity error of frame k (k >= 1 in the frame list, frames k-1 and k both scored): with P
// the estimated and G the ground-truth poses, the motion from k-1 to k expressed in frame
// k-1's coordinates, t_est = trans(P_{k-1}^-1 P_k), t_gt = trans(G_{k-1}^-1 G_k), gives
//   e_k = |t_est - t_gt| / (t_k - t_{k-1})   (m/s).
// It needs no alignment, but both trajectories must be of the same frame (camera or body).
// Its step error |t_est - t_gt| (m) is the same without the division: for an estimate that jumps
// (a late correction applied at once) its largest value is the jump a controller sees.
//
// Gross failures are counted over the whole frame list (the denominator). Frame k is one when
//  * the estimator gave no pose for it (no estimate), or
//  * it has ground truth and e_k exceeds the threshold, or
//  * (option gross_after_gt_gap) it has ground truth and an estimate but frame k-1, which has
//    an estimate, falls in a gap of the ground truth: the first frame after the gap, whose
//    motion cannot be verified (frames before the ground truth starts do not count). This is
//    the convention that reproduces the figures of ../shared/BASELINES.md (see README.md).
// A frame after one the estimator missed is not counted again: that failure is counted once,
// as "no estimate".

#include <cstddef>
#include <cstdint>
#include <vector>

#include "metrics/association.h"
#include "metrics/options.h"
#include "metrics/statistics.h"

namespace kestrel::metrics {

enum class Verdict {
  kChecked,     ///< velocity error computed and within the threshold
  kNotChecked,  ///< an estimate, but no velocity check (first frame, no ground truth at it or
                ///< no estimate at the previous frame, or after a gap with the option off)
  kNoEstimate,  ///< gross: the estimator gave no pose
  kTooFast,     ///< gross: velocity error above the threshold
  kAfterGtGap,  ///< gross: first frame after a ground-truth gap (gross_after_gt_gap)
};

/// True for the verdicts that are gross failures.
bool is_gross(Verdict verdict);

struct GrossFailures {
  size_t frames = 0;  ///< the frame list's length: the denominator
  size_t no_estimate = 0;
  size_t too_fast = 0;
  size_t after_gt_gap = 0;
  size_t total() const { return no_estimate + too_fast + after_gt_gap; }
  double percent() const {
    return frames == 0 ? 0.0 : 100.0 * static_cast<double>(total()) / static_cast<double>(frames);
  }
};

struct VelocityResult {
  Summary error_mps;
  Summary step_error_m;              ///< |t_est - t_gt| per checked frame
  int64_t largest_step_utime = 0;    ///< the frame of step_error_m.max (0: none)
  std::vector<int64_t> utimes;     ///< frame k of each error below
  std::vector<double> errors_mps;  ///< e_k
  std::vector<Verdict> verdicts;   ///< one per frame of the association
  GrossFailures gross;
};

VelocityResult compute_velocity(const Association& association, const EvalOptions& options);

}  // namespace kestrel::metrics
