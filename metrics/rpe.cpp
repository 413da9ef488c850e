#include "metrics/rpe.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/geometry/so3.h"
#include "common/time.h"

namespace kestrel::metrics {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

}  // namespace

RpeResult compute_rpe(const Association& association, double delta_s, double tolerance_s) {
  std::vector<const FramePoses*> scored;
  for (const FramePoses& f : association.frames)
    if (f.scored()) scored.push_back(&f);

  RpeResult result;
  std::vector<double> translation, rotation;
  for (size_t i = 0; i < scored.size(); ++i) {
    const double t_i = to_seconds(scored[i]->utime);
    const double target = t_i + delta_s;
    // First scored frame at or after the target; the closest is it or the one before.
    const auto first_after =
        std::lower_bound(scored.begin() + static_cast<std::ptrdiff_t>(i) + 1, scored.end(), target,
                         [](const FramePoses* f, double t) { return to_seconds(f->utime) < t; });
    size_t j = static_cast<size_t>(first_after - scored.begin());
    if (j > i + 1 && (j == scored.size() || target - to_seconds(scored[j - 1]->utime) <=
                                                to_seconds(scored[j]->utime) - target)) {
      --j;
    }
    if (j >= scored.size()) {
      ++result.no_partner;
      continue;
    }
    const double span = to_seconds(scored[j]->utime - scored[i]->utime);
    if (std::abs(span - delta_s) > tolerance_s) {
      ++result.no_partner;
      continue;
    }
    const Eigen::Isometry3d gt_rel = scored[i]->T_world_gt->inverse() * *scored[j]->T_world_gt;
    const Eigen::Isometry3d est_rel = scored[i]->T_world_est->inverse() * *scored[j]->T_world_est;
    const Eigen::Isometry3d E = gt_rel.inverse() * est_rel;
    translation.push_back(E.translation().norm() / span);
    rotation.push_back(so3::angle(E.linear()) * kDegPerRad / span);
  }
  result.pairs = translation.size();
  result.translation_mps = summarize(std::move(translation));
  result.rotation_degps = summarize(std::move(rotation));
  return result;
}

}  // namespace kestrel::metrics
