#include "tools/flights/flight_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "common/json_number.h"

namespace kestrel::flights {
namespace {

// Mean of the finite values; NaN when there is none.
double mean_of(const std::vector<double>& v) {
  double sum = 0.0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) sum += x, ++n;
  return n > 0 ? sum / n : kNaN;
}

double max_of(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x)) m = std::isnan(m) ? x : std::max(m, x);
  return m;
}

std::string number(double v, const char* format = "{:.3f}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("—");
}

}  // namespace

std::string markdown_table(const std::vector<FlightRow>& rows, const std::string& world, double error_bound_m) {
  std::map<std::pair<int, std::string>, std::vector<const FlightRow*>> groups;
  for (const FlightRow& r : rows)
    if (r.world == world) groups[{r.pair, r.planner}].push_back(&r);
  std::string out = fmt::format(
      "| pair | planner | flights | arrived | arrived, error ≤ {:g} m all the way | true error mean / max (m) | "
      "NEES (3 dof) | inside 3σ | path (m) | time (s) | VO failed / gross | loops | contacts | "
      "tr Σ goal: planned / flown (m²) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      error_bound_m);
  for (const auto& [key, group] : groups) {
    const FlightRow& first = *group.front();
    if (!first.planned) {
      out += fmt::format("| {} | {} | 0 | no path | — | — | — | — | — | — | — | — | — | — |\n", key.first, key.second);
      continue;
    }
    int flown = 0, arrived = 0, within = 0, contacts = 0;
    int64_t vo_failed = 0, vo_gross = 0, vo_frames = 0;
    std::vector<double> mean_err, max_err, nees, inside, time, loops, flown_goal_trace;
    for (const FlightRow* r : group) {
      if (!r->flown) continue;
      ++flown;
      arrived += r->score.arrived;
      // An error never computed (no state scored) is not within any bound.
      within += r->score.arrived && r->score.error_max_m <= error_bound_m;
      contacts += std::max(0, r->contacts);
      vo_failed += r->counts.vo_failures;
      vo_gross += r->counts.vo_gross;
      vo_frames += r->counts.vo_frames;
      mean_err.push_back(r->score.error_mean_m);
      max_err.push_back(r->score.error_max_m);
      nees.push_back(r->score.nees_mean);
      inside.push_back(r->score.inside_3sigma);
      time.push_back(r->score.arrived ? r->score.arrival_s : kNaN);
      loops.push_back(r->counts.loop_closures);
      flown_goal_trace.push_back(r->score.flown_trace.empty() ? kNaN : r->score.flown_trace.back());
    }
    const auto share = [flown](int n) {
      return flown > 0 ? fmt::format("{:.0f} % ({}/{})", 100.0 * n / flown, n, flown) : std::string("—");
    };
    out += fmt::format("| {} | {} | {} | {} | {} | {} / {} | {} | {} | {} | {} | {} / {} of {} | {} | {} | {} / {} |\n",
                       key.first, key.second, flown, share(arrived), share(within), number(mean_of(mean_err)),
                       number(max_of(max_err)),
                       number(mean_of(nees), "{:.1f}"), number(100.0 * mean_of(inside), "{:.0f} %"),
                       number(first.path_length_m, "{:.1f}"), number(mean_of(time), "{:.1f}"), vo_failed, vo_gross,
                       vo_frames, number(mean_of(loops), "{:.1f}"), contacts,
                       number(first.predicted_goal_trace, "{:.4f}"), number(mean_of(flown_goal_trace), "{:.4f}"));
  }
  return out;
}

nlohmann::json to_json(const std::vector<FlightRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const FlightRow& r : rows) {
    nlohmann::json j;
    j["world"] = r.world;
    j["pair"] = r.pair;
    j["planner"] = r.planner;
    j["seed"] = r.seed;
    j["planned"] = r.planned;
    j["flown"] = r.flown;
    if (!r.failure.empty()) j["failure"] = r.failure;
    j["path_length_m"] = r.path_length_m;
    j["predicted_goal_trace_m2"] = finite_or_null(r.predicted_goal_trace);
    j["predicted_max_trace_m2"] = finite_or_null(r.predicted_max_trace);
    if (r.flown) {
      const FlightScore& s = r.score;
      j["arrived"] = s.arrived;
      j["arrival_s"] = finite_or_null(s.arrival_s);
      j["final_distance_m"] = finite_or_null(s.final_distance_m);
      j["flown_s"] = s.flown_s;
      j["states_scored"] = s.states_scored;
      j["true_error_mean_m"] = finite_or_null(s.error_mean_m);
      j["true_error_max_m"] = finite_or_null(s.error_max_m);
      j["nees_mean"] = finite_or_null(s.nees_mean);
      j["inside_3sigma"] = finite_or_null(s.inside_3sigma);
      nlohmann::json flown_trace = nlohmann::json::array();
      for (double t : s.flown_trace) flown_trace.push_back(finite_or_null(t));
      j["flown_trace_at_nodes_m2"] = flown_trace;
      j["contacts"] = r.contacts;
      j["vo_frames"] = r.counts.vo_frames;
      j["vo_failures"] = r.counts.vo_failures;
      j["vo_gross"] = r.counts.vo_gross;
      j["keyframes"] = r.counts.keyframes;
      j["loop_closures"] = r.counts.loop_closures;
    }
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace kestrel::flights
