#pragma once
// What `kestrel fly-plans` reports: one row per flight, and per world a table of start/goal
// pair x planner (success %, true error, consistency, path length, time, the VO and SLAM
// counts, the belief model's prediction beside the flown covariance), as Markdown and JSON.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tools/flights/flight_score.h"

namespace kestrel::flights {

struct FlightRow {
  std::string world;
  int pair = 0;          ///< 1-based, as the experiment numbers them
  std::string planner;   ///< "prm-uniform", "brm-su", ...
  uint64_t seed = 0;
  bool planned = false;  ///< the planner found a path (else nothing was flown)
  bool flown = false;    ///< the flight ran to its end (else `failure` says why)
  std::string failure;
  double path_length_m = 0.0;
  double predicted_goal_trace = kNaN;  ///< belief model: tr of the position covariance at the goal
  double predicted_max_trace = kNaN;   ///< ... its largest along the path
  int contacts = -1;                   ///< the simulator's count of touches of the world
  FlightRecord counts;                 ///< VO and SLAM counts (the samples are not kept)
  FlightScore score;
};

/// The table of one world's rows, one line per pair and planner, flights pooled. Beside
/// "arrived", the flights that arrived with the true error never above `error_bound_m` (the
/// paper's experiment asks both of a BRM plan; fly-plans passes its arrival radius).
std::string markdown_table(const std::vector<FlightRow>& rows, const std::string& world, double error_bound_m);

/// Every row, without the per-state series.
nlohmann::json to_json(const std::vector<FlightRow>& rows);

}  // namespace kestrel::flights
