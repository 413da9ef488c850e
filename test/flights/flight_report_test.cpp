// The fly-plans report on rows made by hand: one line per pair and planner with the flights
// pooled, what arrived and what arrived without the true error ever passing the bound, and a
// pair the planner found no path for.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tools/flights/flight_report.h"

namespace kestrel::flights {
namespace {

FlightRow flight(int pair, const std::string& planner, uint64_t seed, bool arrived, double max_error_m) {
  FlightRow r;
  r.world = "stata";
  r.pair = pair;
  r.planner = planner;
  r.seed = seed;
  r.planned = r.flown = true;
  r.path_length_m = 20.0;
  r.contacts = 0;
  r.score.arrived = arrived;
  r.score.arrival_s = arrived ? 40.0 : kNaN;
  r.score.error_mean_m = max_error_m / 2.0;
  r.score.error_max_m = max_error_m;
  return r;
}

// The line of `pair` and `planner` in `table`, from its first cell.
std::string line_of(const std::string& table, int pair, const std::string& planner) {
  const std::string head = "| " + std::to_string(pair) + " | " + planner + " |";
  const size_t at = table.find(head);
  if (at == std::string::npos) return "";
  return table.substr(at, table.find('\n', at) - at);
}

TEST(FlightReport, ArrivedAndArrivedWithinTheBoundArePooledPerPairAndPlanner) {
  std::vector<FlightRow> rows = {
      flight(1, "brm-su", 1, true, 0.21),   // arrived, within 0.3 m
      flight(1, "brm-su", 2, true, 0.35),   // arrived, once 0.35 m off
      flight(1, "brm-su", 3, false, 0.10),  // within, but did not arrive
      flight(1, "prm-uniform", 1, true, 0.30),  // the bound itself is within
  };
  FlightRow no_path;
  no_path.world = "stata";
  no_path.pair = 4;
  no_path.planner = "brm-su";
  rows.push_back(no_path);
  FlightRow other_world = flight(1, "brm-su", 9, true, 0.01);
  other_world.world = "floor";
  rows.push_back(other_world);

  const std::string table = markdown_table(rows, "stata", 0.3);
  EXPECT_NE(table.find("| arrived | arrived, error ≤ 0.3 m all the way |"), std::string::npos) << table;
  EXPECT_EQ(line_of(table, 1, "brm-su").rfind("| 1 | brm-su | 3 | 67 % (2/3) | 33 % (1/3) | 0.110 / 0.350 |", 0), 0u)
      << table;
  EXPECT_EQ(line_of(table, 1, "prm-uniform").rfind("| 1 | prm-uniform | 1 | 100 % (1/1) | 100 % (1/1) |", 0), 0u)
      << table;
  EXPECT_EQ(line_of(table, 4, "brm-su").rfind("| 4 | brm-su | 0 | no path | — |", 0), 0u) << table;
  // Every line has the header's number of cells.
  size_t cells_in_header = 0, start = 0;
  for (const char c : table.substr(0, table.find('\n'))) cells_in_header += c == '|';
  while ((start = table.find('\n', start)) != std::string::npos && start + 1 < table.size()) {
    const std::string line = table.substr(start + 1, table.find('\n', start + 1) - start - 1);
    size_t cells = 0;
    for (const char c : line) cells += c == '|';
    EXPECT_EQ(cells, cells_in_header) << line;
    ++start;
  }
  EXPECT_EQ(table.find("| 9 |"), std::string::npos) << "another world's rows stay out";

  // A tighter bound counts fewer.
  EXPECT_EQ(line_of(markdown_table(rows, "stata", 0.2), 1, "prm-uniform")
                .rfind("| 1 | prm-uniform | 1 | 100 % (1/1) | 0 % (0/1) |", 0),
            0u);
}

}  // namespace
}  // namespace kestrel::flights
