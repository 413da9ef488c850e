#include "metrics/evaluate.h"

#include <cmath>
#include <string>

#include "common/time.h"

namespace kestrel::metrics {
namespace {

void check(const EvalOptions& o) {
  if (o.gt_max_gap_us < 0 || o.est_max_gap_us < 0)
    throw std::invalid_argument("evaluate: a maximum gap is negative");
  if (!(o.rpe_delta_s > 0.0) || !std::isfinite(o.rpe_delta_s))
    throw std::invalid_argument("evaluate: the RPE step must be positive");
  if (!(o.rpe_tolerance_s >= 0.0) || !std::isfinite(o.rpe_tolerance_s))
    throw std::invalid_argument("evaluate: the RPE tolerance must be >= 0");
  if (!(o.gross_velocity_mps > 0.0))
    throw std::invalid_argument("evaluate: the gross-failure velocity must be positive");
}

std::string span(const std::vector<int64_t>& utimes) {
  if (utimes.empty()) return "none";
  return format_seconds(utimes.front()) + " .. " + format_seconds(utimes.back()) + " s";
}

}  // namespace

std::vector<int64_t> frame_times(const Trajectory& trajectory) {
  std::vector<int64_t> utimes;
  utimes.reserve(trajectory.size());
  for (const StampedPose& p : trajectory.poses()) utimes.push_back(p.utime);
  return utimes;
}

Evaluation evaluate(const std::vector<int64_t>& frame_utimes, const Trajectory& est,
                    const Trajectory& gt, const EvalOptions& options) {
  check(options);
  Evaluation e;
  e.association = associate(frame_utimes, est, gt, options);
  if (e.association.scored == 0) {
    throw NoOverlapError("no frame has both an estimate and ground truth (frames " +
                         span(frame_utimes) + ", " + std::to_string(e.association.no_estimate) +
                         " without an estimate; ground truth " + span(frame_times(gt)) + ", " +
                         std::to_string(e.association.no_ground_truth()) + " frames without it)");
  }
  e.ate = compute_ate(e.association, options.align);
  e.rpe = compute_rpe(e.association, options.rpe_delta_s, options.rpe_tolerance_s);
  e.velocity = compute_velocity(e.association, options);
  return e;
}

}  // namespace kestrel::metrics
