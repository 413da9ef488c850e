#include "tools/flights/flight_score.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "estimator/eval/consistency.h"

namespace kestrel::flights {
namespace {

double seconds(int64_t us) { return 1e-6 * static_cast<double>(us); }

}  // namespace

FlightScore score_flight(const FlightRecord& r, const Eigen::Vector3d& goal, double radius_m, const PlannedPath& plan) {
  if (r.truth.empty()) throw std::invalid_argument("the flight's recording holds no GROUND_TRUTH");
  FlightScore s;
  const int64_t t0 = r.truth.front().utime;
  s.flown_s = seconds(r.truth.back().utime - t0);
  s.final_distance_m = (r.truth.back().p - goal).norm();
  s.arrived = s.final_distance_m <= radius_m;
  // Arrival: the first truth sample from which on the vehicle stays within the radius.
  if (s.arrived) {
    size_t i = r.truth.size();
    while (i > 0 && (r.truth[i - 1].p - goal).norm() <= radius_m) --i;
    s.arrival_s = seconds(r.truth[i].utime - t0);
  }

  std::unordered_map<int64_t, size_t> truth_at;
  truth_at.reserve(r.truth.size());
  for (size_t i = 0; i < r.truth.size(); ++i) truth_at.emplace(r.truth[i].utime, i);
  double sum = 0.0, nees_sum = 0.0;
  int64_t inside = 0, nees_count = 0;
  std::vector<const StateSample*> scored_states;
  for (const StateSample& st : r.states) {
    if (!st.usable) continue;
    const auto t = truth_at.find(st.utime);
    if (t == truth_at.end()) continue;
    const Eigen::Vector3d e = st.p - r.truth[t->second].p;
    const double d = e.norm();
    s.errors_m.push_back(d);
    s.error_utimes.push_back(st.utime);
    scored_states.push_back(&st);
    sum += d;
    s.error_max_m = std::isnan(s.error_max_m) ? d : std::max(s.error_max_m, d);
    if (!st.P.allFinite()) continue;
    double nees = kNaN;
    try {
      nees = estimator::nees(e, st.P);
    } catch (const std::invalid_argument&) {
      continue;  // a covariance that is not positive definite says nothing of consistency
    }
    if (std::isfinite(nees)) {
      nees_sum += nees;
      ++nees_count;
      inside += nees < kChi2ThreeDof3Sigma;
    }
  }
  s.states_scored = static_cast<int64_t>(s.errors_m.size());
  if (s.states_scored > 0) s.error_mean_m = sum / static_cast<double>(s.states_scored);
  if (nees_count > 0) {
    s.nees_mean = nees_sum / static_cast<double>(nees_count);
    s.inside_3sigma = static_cast<double>(inside) / static_cast<double>(nees_count);
  }

  // STATE's covariance where the true track passed each planned node: walk the scored states
  // in time, each node taking the nearest state after the previous node's.
  size_t from = 0;
  for (const Eigen::Vector3d& node : plan.nodes) {
    double best = std::numeric_limits<double>::infinity();
    size_t best_i = from;
    for (size_t i = from; i < scored_states.size(); ++i) {
      const double d = (r.truth[truth_at.at(scored_states[i]->utime)].p - node).norm();
      if (d < best) best = d, best_i = i;
    }
    s.flown_trace.push_back(best_i < scored_states.size() ? scored_states[best_i]->P.trace() : kNaN);
    from = best_i;
  }
  return s;
}

}  // namespace kestrel::flights
