#pragma once
// Absolute trajectory error: the distance between each scored frame's ground-truth position
// and its estimated position after the rigid alignment of metrics/alignment.h (or none).

#include <cstdint>
#include <vector>

#include "metrics/alignment.h"
#include "metrics/association.h"
#include "metrics/statistics.h"

namespace kestrel::metrics {

struct AteResult {
  Alignment alignment;           ///< maps the estimate's world into the ground truth's
  Summary error_m;               ///< over the scored frames, metres
  std::vector<int64_t> utimes;   ///< the scored frames, in order
  std::vector<double> errors_m;  ///< |p_gt - T_gt_est * p_est| per scored frame
};

/// ATE over the scored frames of `association`; with `align` false the estimate is compared
/// as it is. No scored frame gives an empty summary.
AteResult compute_ate(const Association& association, bool align);

}  // namespace kestrel::metrics
