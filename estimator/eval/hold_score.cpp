#include "estimator/eval/hold_score.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/numbers.h"

namespace kestrel::estimator {
namespace {

class SpreadSum {
 public:
  void add(double d) {
    sum_ += d;
    s_.max = std::max(s_.max, d);
    ++s_.samples;
  }
  Spread get() const {
    Spread s = s_;
    s.mean = s.samples > 0 ? sum_ / static_cast<double>(s.samples) : 0.0;
    return s;
  }

 private:
  Spread s_;
  double sum_ = 0.0;
};

bool in_time_order(const std::vector<TimedPosition>& v) {
  return std::is_sorted(v.begin(), v.end(),
                        [](const TimedPosition& a, const TimedPosition& b) { return a.utime < b.utime; });
}

}  // namespace

HoldScore score_hold(const std::vector<TimedPosition>& truth,
                     const std::vector<TimedPosition>& estimate, const Eigen::Vector3d& target,
                     double from_s, int64_t match_tolerance_us) {
  if (truth.empty()) throw std::invalid_argument("hold score: no ground truth");
  if (!in_time_order(truth) || !in_time_order(estimate))
    throw std::invalid_argument("hold score: samples out of time order");
  const int64_t begin = truth.front().utime + static_cast<int64_t>(std::llround(from_s * 1e6));
  const int64_t end = truth.back().utime;
  if (begin > end) throw std::invalid_argument("hold score: no ground truth after the start of the window");

  HoldScore out;
  out.scored_from_s = from_s;
  out.scored_to_s = 1e-6 * static_cast<double>(end - truth.front().utime);
  SpreadSum th, t3, eh, e3, ey;
  for (const auto& t : truth) {
    if (t.utime < begin) continue;
    const Eigen::Vector3d d = t.p - target;
    th.add(d.head<2>().norm());
    t3.add(d.norm());
  }
  auto later = [](const TimedPosition& t, int64_t u) { return t.utime < u; };
  for (const auto& e : estimate) {
    if (e.utime < begin || e.utime > end) continue;
    const auto hi = std::lower_bound(truth.begin(), truth.end(), e.utime, later);
    auto nearest = hi;
    if (hi == truth.end() || (hi != truth.begin() && e.utime - std::prev(hi)->utime < hi->utime - e.utime))
      nearest = std::prev(hi);
    if (std::llabs(nearest->utime - e.utime) > match_tolerance_us) {
      ++out.unmatched_estimates;
      continue;
    }
    const Eigen::Vector3d d = nearest->p - e.p;
    eh.add(d.head<2>().norm());
    e3.add(d.norm());
    ey.add(std::abs(std::remainder(nearest->yaw - e.yaw, 2.0 * kPi)));
  }
  out.truth_horizontal = th.get();
  out.truth_3d = t3.get();
  out.error_horizontal = eh.get();
  out.error_3d = e3.get();
  out.error_yaw = ey.get();
  return out;
}

}  // namespace kestrel::estimator
