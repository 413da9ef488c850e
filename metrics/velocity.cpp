#include "metrics/velocity.h"

#include "common/time.h"

namespace kestrel::metrics {

bool is_gross(Verdict verdict) {
  return verdict == Verdict::kNoEstimate || verdict == Verdict::kTooFast ||
         verdict == Verdict::kAfterGtGap;
}

VelocityResult compute_velocity(const Association& association, const EvalOptions& options) {
  VelocityResult result;
  const std::vector<FramePoses>& frames = association.frames;
  result.gross.frames = frames.size();
  result.verdicts.reserve(frames.size());
  std::vector<double> steps;
  size_t largest = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    const FramePoses& cur = frames[k];
    const FramePoses* prev = k > 0 ? &frames[k - 1] : nullptr;
    Verdict verdict = Verdict::kNotChecked;
    if (!cur.T_world_est) {
      verdict = Verdict::kNoEstimate;
      ++result.gross.no_estimate;
    } else if (!cur.T_world_gt || !prev || !prev->T_world_est) {
      verdict = Verdict::kNotChecked;
    } else if (!prev->T_world_gt) {
      if (options.gross_after_gt_gap && prev->gt_missing == GtMissing::kInGap) {
        verdict = Verdict::kAfterGtGap;
        ++result.gross.after_gt_gap;
      }
    } else {
      const Eigen::Vector3d t_est = (prev->T_world_est->inverse() * *cur.T_world_est).translation();
      const Eigen::Vector3d t_gt = (prev->T_world_gt->inverse() * *cur.T_world_gt).translation();
      const double step = (t_est - t_gt).norm();
      const double error = step / to_seconds(cur.utime - prev->utime);
      if (steps.empty() || step > steps[largest]) largest = steps.size();
      steps.push_back(step);
      result.utimes.push_back(cur.utime);
      result.errors_mps.push_back(error);
      verdict = Verdict::kChecked;
      if (error > options.gross_velocity_mps) {
        verdict = Verdict::kTooFast;
        ++result.gross.too_fast;
      }
    }
    result.verdicts.push_back(verdict);
  }
  result.error_mps = summarize(result.errors_mps);
  result.step_error_m = summarize(steps);
  if (!steps.empty()) result.largest_step_utime = result.utimes[largest];
  return result;
}

}  // namespace kestrel::metrics
