// The shared trial: build, search, fly.
#include "planner/eval/experiment.h"

#include <chrono>
#include <stdexcept>

#include "planner/samplers.h"

namespace kestrel::planner::eval {
namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

double path_length(const std::vector<Config>& path) {
  double len = 0.0;
  for (size_t i = 1; i < path.size(); ++i) len += ConfigurationSpace::distance(path[i - 1], path[i]);
  return len;
}

std::vector<double> fly(const std::vector<Config>& path, const BeliefModel& model, const Mat4& start_covariance) {
  std::vector<double> traces{start_covariance.trace()};
  Mat4 sigma = start_covariance;
  for (size_t i = 1; i < path.size(); ++i)
    for (const BeliefStep& s : model.steps(path[i - 1], path[i])) {
      sigma = propagate_ekf(sigma, {s});
      traces.push_back(sigma.trace());
    }
  return traces;
}

std::vector<Mat4> node_covariances(const std::vector<Config>& path, const BeliefModel& model,
                                   const Mat4& start_covariance) {
  std::vector<Mat4> out;
  if (path.empty()) return out;
  out.push_back(start_covariance);
  for (size_t i = 1; i < path.size(); ++i) out.push_back(propagate_ekf(out.back(), model.steps(path[i - 1], path[i])));
  return out;
}

Trial run_trial(const Scenario& sc, const Setting& setting, const Config& start, const Config& goal, uint64_t seed) {
  if (setting.planner != "brm" && setting.planner != "brm-dominance" && setting.planner != "prm")
    throw std::invalid_argument("unknown planner '" + setting.planner + "' (brm, brm-dominance, prm)");
  const ConfigurationSpace space(*sc.env, sc.space);
  const FeatureSensor sensor(*sc.env, sc.sensor);
  const BeliefModel model(sc.motion, [&sensor](const Config& q) { return sensor.information(q); });
  Rng rng(seed);
  auto sampler = make_sampler(setting.sampler, space, sensor, sc.ukf_prior);
  RoadmapOptions options = sc.roadmap;
  options.samples = setting.samples;
  const bool brm = setting.planner != "prm";

  Trial t;
  const auto t0 = std::chrono::steady_clock::now();
  const Roadmap map = build_roadmap(space, *sampler, start, goal, options, brm ? &model : nullptr, rng);
  t.build_s = seconds_since(t0);
  for (int i = 2; i < map.size(); ++i) t.samples.push_back(map.node(i));

  const auto t1 = std::chrono::steady_clock::now();
  PlanResult r;
  if (brm) {
    BrmQuery q;
    q.start_covariance = sc.start_covariance;
    if (setting.max_trace > 0.0) {
      q.objective = BrmObjective::kShortestBounded;
      q.max_trace = setting.max_trace;
    }
    if (setting.planner == "brm-dominance") {
      q.pruning = BrmPruning::kCovarianceDominance;
      q.dominance_slack = setting.dominance_slack;
    }
    r = belief_search(map, 0, 1, q);
  } else {
    r = shortest_path(map, 0, 1);
  }
  t.search_s = seconds_since(t1);
  t.found = r.found;
  if (!r.found) return t;
  for (int n : r.nodes) t.path.push_back(map.node(n));
  t.length_m = r.length_m;
  const std::vector<double> traces = fly(t.path, model, sc.start_covariance);
  t.goal_trace = traces.back();
  t.max_trace = *std::max_element(traces.begin(), traces.end());
  t.success = t.max_trace < sc.max_trace;
  return t;
}

}  // namespace kestrel::planner::eval
