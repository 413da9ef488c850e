// OnlinePlanner: request validation, roadmap, search, predicted covariances.
#include "planner/online_planner.h"

#include "planner/grid_environment.h"

namespace kestrel::planner {

OnlinePlanner::OnlinePlanner(OnlinePlannerOptions options) : options_(std::move(options)) {}

void OnlinePlanner::set_map(OccupancyGrid grid) {
  env_ = std::make_unique<GridEnvironment>(std::move(grid), options_.map_z_min_m, options_.map_z_max_m);
  env_->set_features(env_->wall_features(options_.feature_density_per_m2, 2.0, 1));
}

void OnlinePlanner::set_state(const Config& q, const Mat4& covariance) { state_ = {q, covariance}; }

void OnlinePlanner::reset() {
  env_.reset();
  state_.reset();
}

PlanAnswer OnlinePlanner::plan(const PlanQuery& query) const {
  PlanAnswer a;
  if (!env_) {
    a.message = "no map yet";
    return a;
  }
  if (!query.goal.allFinite() || (query.start && (!query.start->allFinite() || !(query.start_trace > 0.0))) ||
      std::isnan(query.max_trace) || !(query.max_trace > 0.0)) {
    a.status = PlanAnswer::kBadRequest;
    a.message = "start, goal, start covariance or bound not finite and positive";
    return a;
  }
  if (!query.start && !state_) {
    a.status = PlanAnswer::kBadRequest;
    a.message = "start from state requested, but no STATE received";
    return a;
  }
  const Config start = query.start ? *query.start : state_->first;
  const Mat4 sigma0 = query.start ? Mat4((query.start_trace / 4.0) * Mat4::Identity()) : state_->second;
  const ConfigurationSpace space(*env_, options_.space);
  if (!space.is_valid(start)) {
    a.status = PlanAnswer::kStartInCollision;
    a.message = "start is not in known free space";
    return a;
  }
  if (!space.is_valid(query.goal)) {
    a.status = PlanAnswer::kGoalInCollision;
    a.message = "goal is not in known free space";
    return a;
  }
  const FeatureSensor sensor(*env_, options_.sensor);
  const BeliefModel model(options_.motion, [&](const Config& q) { return sensor.information(q); });
  std::unique_ptr<Sampler> sampler;
  const double range = options_.sensor.max_range_m;
  if (options_.sampler == "uniform") sampler = make_uniform_sampler(space);
  else if (options_.sampler == "gaussian") sampler = make_gaussian_sampler(space, range);
  else if (options_.sampler == "bridge") sampler = make_bridge_sampler(space, 2.0 * range);
  else sampler = make_sensor_sampler(space, [&](const Config& q) { return sensor.information(q).trace(); });
  Rng rng(static_cast<uint64_t>(query.request_id) * 0x9E3779B97F4A7C15ull + 1);
  const Roadmap map = build_roadmap(space, *sampler, start, query.goal, options_.roadmap, query.brm ? &model : nullptr, rng);
  PlanResult r;
  if (query.brm) {
    BrmQuery q;
    q.start_covariance = sigma0;
    q.objective = query.objective;
    q.max_trace = query.max_trace;
    r = belief_search(map, 0, 1, q);
  } else {
    r = shortest_path(map, 0, 1);
  }
  if (!r.found) {
    a.status = PlanAnswer::kNoPath;
    a.message = "no path in a roadmap of " + std::to_string(map.size()) + " nodes";
    return a;
  }
  a.status = PlanAnswer::kOk;
  a.length_m = r.length_m;
  Mat4 sigma = sigma0;
  for (size_t i = 0; i < r.nodes.size(); ++i) {
    const Config& q = map.node(r.nodes[i]);
    if (i > 0) sigma = propagate_ekf(sigma, model.steps(a.waypoints.back(), q));
    a.waypoints.push_back(q);
    a.traces.push_back(sigma.trace());
  }
  return a;
}

}  // namespace kestrel::planner
