#pragma once
// Relative pose error over a time step delta (Sturm et al., IROS 2012), as a rate.
//
// Pairs: for every scored frame i, j is the scored frame after i whose time is closest to
// t_i + delta (the earlier one on a tie); the pair is used only if |t_j - t_i - delta| is
// within the tolerance (so a pair never straddles a long gap unnoticed, and frames within
// delta of the end have no pair). With G the ground-truth and P the estimated poses,
//   E = (G_i^-1 G_j)^-1 (P_i^-1 P_j),
// translational error |trans(E)| / (t_j - t_i) in m/s and rotational error
// angle(E) / (t_j - t_i) in deg/s. Both are independent of either trajectory's world frame,
// so no alignment is involved. TUM reports the RMSE.

#include <cstddef>

#include "metrics/association.h"
#include "metrics/statistics.h"

namespace kestrel::metrics {

struct RpeResult {
  Summary translation_mps;
  Summary rotation_degps;
  size_t pairs = 0;
  size_t no_partner = 0;  ///< scored frames with no partner within the tolerance
};

RpeResult compute_rpe(const Association& association, double delta_s, double tolerance_s);

}  // namespace kestrel::metrics
