// OnlinePlanner: request validation, roadmap, search, predicted covariances.
#include "planner/online_planner.h"

#include <algorithm>
#include <cmath>

#include "planner/grid_environment.h"
#include "planner/samplers.h"

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

std::unique_ptr<GridEnvironment> OnlinePlanner::with_vehicle_space(const Config& q) const {
  const OccupancyGrid& map = env_->grid();
  // At least the cells whose centres lie within the vehicle's radius plus one cell: the
  // conservative clearance (grid_environment.h) then sees free space all round the vehicle.
  const double reach = std::max(options_.start_unknown_free_m, options_.space.radius_m + map.resolution);
  const Eigen::Vector2d centre = map.T_world_grid.inverse() * q.head<2>();
  const int cells = static_cast<int>(std::ceil(reach / map.resolution)) + 2;  // and the border cell
  const int c_lo = static_cast<int>(std::floor(centre.x())) - cells, c_hi = static_cast<int>(std::ceil(centre.x())) + cells;
  const int r_lo = static_cast<int>(std::floor(centre.y())) - cells, r_hi = static_cast<int>(std::ceil(centre.y())) + cells;
  // The map may end at the camera: the vehicle behind it is then off the grid. Grow the grid
  // (unknown) to hold the vehicle's surroundings.
  const int pad_c = std::max(0, -c_lo), pad_r = std::max(0, -r_lo);
  OccupancyGrid grid;
  grid.resolution = map.resolution;
  grid.width = std::max(map.width, c_hi + 1) + pad_c;
  grid.height = std::max(map.height, r_hi + 1) + pad_r;
  grid.T_world_grid = map.T_world_grid * Eigen::Translation2d(-pad_c, -pad_r);
  grid.cells.assign(static_cast<size_t>(grid.width) * static_cast<size_t>(grid.height), OccupancyGrid::kUnknown);
  for (int row = 0; row < map.height; ++row)
    std::copy_n(&map.cells[static_cast<size_t>(row) * static_cast<size_t>(map.width)], map.width,
                &grid.cells[static_cast<size_t>(row + pad_r) * static_cast<size_t>(grid.width) + static_cast<size_t>(pad_c)]);
  bool changed = grid.width != map.width || grid.height != map.height;
  for (int row = r_lo + pad_r; row <= r_hi + pad_r; ++row) {
    for (int col = c_lo + pad_c; col <= c_hi + pad_c; ++col) {
      const Eigen::Vector2d xy = grid.T_world_grid * Eigen::Vector2d(col, row);
      if ((xy - q.head<2>()).norm() > reach) continue;
      uint8_t& cell = grid.cells[static_cast<size_t>(row) * static_cast<size_t>(grid.width) + static_cast<size_t>(col)];
      if (cell == OccupancyGrid::kUnknown) {
        cell = OccupancyGrid::kFree;
        changed = true;
      }
    }
  }
  if (!changed) return nullptr;
  auto env = std::make_unique<GridEnvironment>(std::move(grid), options_.map_z_min_m, options_.map_z_max_m);
  env->set_features(env_->features());
  return env;
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
  // Starting from the vehicle's state: the space the vehicle fills is free (it is there), even
  // where the map has never seen it (behind and beside the camera, inside its minimum range).
  std::unique_ptr<GridEnvironment> around_vehicle;
  if (!query.start) around_vehicle = with_vehicle_space(start);
  const GridEnvironment& env = around_vehicle ? *around_vehicle : *env_;
  const ConfigurationSpace space(env, options_.space);
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
  const FeatureSensor sensor(env, options_.sensor);
  const BeliefModel model(options_.motion, [&](const Config& q) { return sensor.information(q); });
  // su-ukf measures the information gain against the start's covariance.
  const std::unique_ptr<Sampler> sampler = make_sampler(options_.sampler, space, sensor, sigma0);
  Rng rng(static_cast<uint64_t>(query.request_id) * 0x9E3779B97F4A7C15ull + 1);
  const Roadmap map = build_roadmap(space, *sampler, start, query.goal, options_.roadmap, query.brm ? &model : nullptr, rng);
  PlanResult r;
  if (query.brm) {
    BrmQuery q;
    q.start_covariance = sigma0;
    q.objective = query.objective;
    q.max_trace = query.max_trace;
    q.pruning = query.pruning;
    q.dominance_slack = query.dominance_slack;
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
    a.covariances.push_back(sigma);
  }
  return a;
}

}  // namespace kestrel::planner
