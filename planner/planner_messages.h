#pragma once
// The planner process's messages, checked and converted: what kestrel-planner (main.cpp)
// takes from STATE, PLAN_REQUEST and MAP_OCTOMAP, and the PLAN it answers with.
//
// Every function throws InputError naming the channel and the field for a message it cannot
// use; nothing it refuses reaches the planner. A request is refused, before any planning,
// when a number it uses is not finite, a position is beyond kMaxPlanCoordinate_m, a
// covariance trace is negative (or, as a bound, not positive), or its start mode, planner or
// objective is none this version knows.

#include <optional>
#include <utility>

#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_covariance_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"
#include "planner/grid_environment.h"
#include "planner/online_planner.h"
#include "planner/types.h"

namespace kestrel::planner {

/// Farthest a start or goal may be from the world's origin (m): the planner's maps are at
/// most 1 km across (drivers/sim/occupancy_map.h) and never placed farther out than 10 km.
inline constexpr double kMaxPlanCoordinate_m = 1e4;

/// STATE -> the configuration (x, y, z, yaw) and the 4 x 4 covariance of [dp; dyaw] (dyaw ~
/// dtheta_z, body); the identity when the state carries no covariance.
std::pair<Config, Mat4> state_from_message(const kestrel::state_t& s);

/// PLAN_REQUEST -> the query; `dominance_slack` for PLANNER_BRM_DOMINANCE requests.
PlanQuery query_from_message(const kestrel::plan_request_t& r, double dominance_slack);

/// MAP_OCTOMAP -> the floor plan of its occupied and free cells over [z_min, z_max] (m).
OccupancyGrid map_from_message(const kestrel::octomap_t& m, double z_min, double z_max);

/// The PLAN answering `r`.
kestrel::plan_t plan_message(const kestrel::plan_request_t& r, const PlanAnswer& answer, double planning_ms);
/// The PLAN_COVARIANCE that goes with `plan` (its utime, request_id and waypoints), from the
/// answer it was made of; none when the answer has no covariances (no path).
std::optional<kestrel::plan_covariance_t> plan_covariance_message(const kestrel::plan_t& plan, const PlanAnswer& answer);

}  // namespace kestrel::planner
