#pragma once
// One evaluation of an estimated trajectory against ground truth: association, then ATE, RPE,
// velocity error and gross failures (each defined in its own header).

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "common/trajectory.h"
#include "metrics/association.h"
#include "metrics/ate.h"
#include "metrics/options.h"
#include "metrics/rpe.h"
#include "metrics/velocity.h"

namespace kestrel::metrics {

/// No frame has both an estimate and ground truth: nothing can be scored.
class NoOverlapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Evaluation {
  Association association;
  AteResult ate;
  RpeResult rpe;
  VelocityResult velocity;
};

/// Evaluates `est` against `gt` at `frame_utimes` (strictly increasing). Both trajectories
/// must already be of the same frame (camera or body). Throws NoOverlapError when no frame is
/// scored, std::invalid_argument for unusable options.
Evaluation evaluate(const std::vector<int64_t>& frame_utimes, const Trajectory& est,
                    const Trajectory& gt, const EvalOptions& options);

/// The time stamps of `trajectory`: the default frame list.
std::vector<int64_t> frame_times(const Trajectory& trajectory);

}  // namespace kestrel::metrics
