#include "planner/planner_messages.h"

#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "common/error.h"
#include "common/text.h"
#include "common/transport/convert.h"
#include "mapper/octree_io.h"
#include "planner/map_sources.h"

namespace kestrel::planner {
namespace {

constexpr const char* kRequest = "PLAN_REQUEST";

void check_position(const double (&q)[4], const char* field) {
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(q[i])) throw InputError(std::string(kRequest) + ": " + field + " is not finite");
  }
  for (int i = 0; i < 3; ++i) {
    if (std::abs(q[i]) > kMaxPlanCoordinate_m) {
      throw InputError(std::string(kRequest) + ": " + field + " is farther than " +
                       number_text(kMaxPlanCoordinate_m) + " m from the origin");
    }
  }
}

void check_trace(double trace, const char* field, bool zero_allowed) {
  if (!std::isfinite(trace) || trace < 0.0 || (!zero_allowed && trace == 0.0)) {
    throw InputError(std::string(kRequest) + ": " + field + " must be a finite number " +
                     (zero_allowed ? ">= 0" : "> 0") + ", got " + number_text(trace));
  }
}

}  // namespace

std::pair<Config, Mat4> state_from_message(const kestrel::state_t& s) {
  const auto& p = s.T_world_body.position;
  const auto& o = s.T_world_body.orientation;
  const Eigen::Quaterniond q(o[0], o[1], o[2], o[3]);
  if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) throw InputError("STATE: orientation not a unit quaternion");
  const Eigen::Matrix3d R = q.toRotationMatrix();
  Config c(p[0], p[1], p[2], std::atan2(R(1, 0), R(0, 0)));
  if (!c.allFinite()) throw InputError("STATE: position not finite");
  Mat4 cov = Mat4::Identity();
  if (s.cov_dim >= 9) {
    // x, y, z and the rotation about body z (the heading, for a level vehicle).
    const Matrix6d pose = transport::pose_covariance_from(s);
    const int idx[4] = {0, 1, 2, 5};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) cov(i, j) = pose(idx[i], idx[j]);
  }
  if (!cov.allFinite()) throw InputError("STATE: covariance not finite");
  return {c, cov};
}

PlanQuery query_from_message(const kestrel::plan_request_t& r, double dominance_slack) {
  using R = kestrel::plan_request_t;
  if (r.start_mode != R::START_FROM_STATE && r.start_mode != R::START_GIVEN) {
    throw InputError(std::string(kRequest) + ": unknown start mode " + std::to_string(r.start_mode));
  }
  if (r.planner != R::PLANNER_BRM && r.planner != R::PLANNER_PRM && r.planner != R::PLANNER_BRM_DOMINANCE) {
    throw InputError(std::string(kRequest) + ": unknown planner " + std::to_string(r.planner));
  }
  if (r.objective != R::OBJECTIVE_SHORTEST_BOUNDED && r.objective != R::OBJECTIVE_MIN_GOAL_UNCERTAINTY) {
    throw InputError(std::string(kRequest) + ": unknown objective " + std::to_string(r.objective));
  }
  PlanQuery q;
  q.request_id = static_cast<long>(r.request_id);
  if (r.start_mode == R::START_GIVEN) {
    check_position(r.start, "start");
    check_trace(r.start_covariance_trace, "start_covariance_trace", true);
    q.start = Config(r.start[0], r.start[1], r.start[2], r.start[3]);
    q.start_trace = r.start_covariance_trace;
  }
  check_position(r.goal, "goal");
  q.goal = Config(r.goal[0], r.goal[1], r.goal[2], r.goal[3]);
  q.brm = r.planner != R::PLANNER_PRM;
  if (r.planner == R::PLANNER_BRM_DOMINANCE) {
    q.pruning = BrmPruning::kCovarianceDominance;
    q.dominance_slack = dominance_slack;
  }
  if (r.objective == R::OBJECTIVE_SHORTEST_BOUNDED) {
    check_trace(r.max_covariance_trace, "max_covariance_trace", false);
    q.objective = BrmObjective::kShortestBounded;
    q.max_trace = r.max_covariance_trace;
  } else {
    q.objective = BrmObjective::kMinGoalUncertainty;
  }
  return q;
}

OccupancyGrid map_from_message(const kestrel::octomap_t& m, double z_min, double z_max) {
  if (m.size != static_cast<int32_t>(m.data.size())) throw InputError("MAP_OCTOMAP: size disagrees with data");
  const auto format = m.format == kestrel::octomap_t::FORMAT_BINARY ? mapper::OctreeFormat::kBinary
                                                                    : mapper::OctreeFormat::kFull;
  const auto tree = mapper::read_octree(m.data.data(), m.data.size(), format, "MAP_OCTOMAP");
  return project_octomap(*tree, z_min, z_max, "MAP_OCTOMAP");
}

kestrel::plan_t plan_message(const kestrel::plan_request_t& r, const PlanAnswer& a, double planning_ms) {
  kestrel::plan_t out;
  out.utime = r.utime;
  out.request_id = r.request_id;
  out.status = static_cast<int8_t>(a.status);  // the enums share their order
  out.message = a.message;
  out.num_waypoints = static_cast<int32_t>(a.waypoints.size());
  for (size_t i = 0; i < a.waypoints.size(); ++i) {
    out.waypoints.push_back({a.waypoints[i][0], a.waypoints[i][1], a.waypoints[i][2], a.waypoints[i][3]});
    out.covariance_trace.push_back(a.traces[i]);
  }
  out.length = a.length_m;
  out.planning_ms = planning_ms;
  return out;
}

std::optional<kestrel::plan_covariance_t> plan_covariance_message(const kestrel::plan_t& plan, const PlanAnswer& a) {
  if (a.covariances.empty() || a.covariances.size() != static_cast<size_t>(plan.num_waypoints)) return std::nullopt;
  kestrel::plan_covariance_t out;
  out.utime = plan.utime;
  out.request_id = plan.request_id;
  out.num_waypoints = plan.num_waypoints;
  for (const Mat4& sigma : a.covariances) {
    std::vector<double> row_major(16);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) row_major[static_cast<size_t>(4 * r + c)] = sigma(r, c);
    out.covariance.push_back(std::move(row_major));
  }
  return out;
}

}  // namespace kestrel::planner
