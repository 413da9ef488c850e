#pragma once
// The paper's planning experiments (§4: Tables 3-5, Figs. 7, 12/13, the laser validation) and
// ours (transfer precision), each as a Markdown table with the paper's figures beside ours.
// Every function takes its seed; the same arguments give the same table (times aside).

#include <string>
#include <utility>
#include <vector>

#include "planner/eval/experiment.h"

namespace kestrel::planner::eval {

struct ExperimentOptions {
  int trials = 30;
  int samples = 100;
  uint64_t seed = 1;
};

using Pairs = std::vector<std::pair<Config, Config>>;

std::string table3_weight_cost(uint64_t seed);
std::string table4_samplers(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o);
std::string table5_planners(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o);
std::string fig7_ukf_transfer(const Scenario& sc, const ExperimentOptions& o);
std::string fig12_sample_counts(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o,
                                const std::vector<int>& counts);
std::string laser_experiment(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o,
                             double short_range_m, double long_range_m, double bound);
std::string transfer_precision(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o);

}  // namespace kestrel::planner::eval
