// kestrel-planner: the planning process. MAP_OCTOMAP (projected over the flight band),
// STATE and PLAN_REQUEST in, PLAN out; the work is OnlinePlanner's. See planner/README.md.
#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/state_t.hpp"
#include "mapper/octree_io.h"
#include "planner/map_sources.h"
#include "planner/online_planner.h"

#include <octomap/OcTree.h>

namespace {

using namespace kestrel;
using namespace kestrel::planner;

// STATE -> (x, y, z, yaw) and the 4 x 4 covariance of [dp; dyaw] (dyaw ~ dtheta_z, body).
std::pair<Config, Mat4> from_state(const kestrel::state_t& s) {
  const auto& p = s.T_world_body.position;
  const auto& o = s.T_world_body.orientation;
  const Eigen::Quaterniond q(o[0], o[1], o[2], o[3]);
  if (!std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) throw InputError("STATE: orientation not a unit quaternion");
  const Eigen::Matrix3d R = q.toRotationMatrix();
  Config c(p[0], p[1], p[2], std::atan2(R(1, 0), R(0, 0)));
  if (!c.allFinite()) throw InputError("STATE: position not finite");
  Mat4 cov = Mat4::Identity();
  if (s.cov_dim >= 9) {
    const int idx[4] = {0, 1, 2, 8};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) cov(i, j) = s.covariance[idx[i]][idx[j]];
  }
  if (!cov.allFinite()) throw InputError("STATE: covariance not finite");
  return {c, cov};
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("planner", "Belief Roadmap planner: MAP_OCTOMAP + STATE + PLAN_REQUEST -> PLAN");
  OnlinePlannerOptions o;
  std::string lcm_url, sensor = "kinect";
  double height = 1.0;
  app.add_option("--lcm-url", lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--radius", o.space.radius_m, "Vehicle radius (m)")->check(cli::Positive);
  app.add_option("--height", height, "Flight height of the roadmap's samples (m)")->check(cli::Positive);
  app.add_option("--map-z-min", o.map_z_min_m, "Lowest map height that counts for collisions (m)");
  app.add_option("--map-z-max", o.map_z_max_m, "Highest map height that counts for collisions (m)");
  app.add_option("--samples", o.roadmap.samples, "Roadmap samples (drawn again while start and goal are not connected)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--max-samples", o.roadmap.max_samples, "Most samples a roadmap grows to (<= --samples: no growth)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--connect-radius", o.roadmap.connect_radius_m, "Longest edge (m)")->check(cli::Positive);
  app.add_option("--sampler", o.sampler, "uniform, su, gaussian, bridge")
      ->check(CLI::IsMember({"uniform", "su", "gaussian", "bridge"}));
  app.add_option("--sensor", sensor, "kinect or camera (the paper's)")->check(CLI::IsMember({"kinect", "camera"}));
  app.add_option("--feature-density", o.feature_density_per_m2, "Features assumed per m^2 of wall")->check(cli::Positive);
  double dominance_slack = kToolsDominanceSlack;
  app.add_option("--dominance-slack", dominance_slack,
                 "PLANNER_BRM_DOMINANCE requests: a label is also dropped when one kept at its node is within this "
                 "fraction of dominating it (0: exact dominance, slow on large roadmaps)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--start-unknown-free", o.start_unknown_free_m,
                 "Unknown map cells within this of the vehicle count as free when planning from STATE (m): the "
                 "camera cannot see the space around the vehicle")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  return app.run(argc, argv, [&]() -> int {
    o.space.z_min_m = o.space.z_max_m = height;
    o.sensor = sensor == "kinect" ? FeatureSensorOptions::kinect() : FeatureSensorOptions::paper_camera();
    OnlinePlanner planner(o);
    transport::Node node("planner", lcm_url);
    node.advertise(channel::kPlan);
    node.set_health(kestrel::process_status_t::STATE_DEGRADED, "no map yet");
    // The mapper sends its last map again while it has no new one (for a planner started since):
    // the one held already is not projected again.
    std::optional<std::pair<int64_t, int64_t>> held_map;  // revision, utime
    node.subscribe<kestrel::octomap_t>(channel::kMapOctomap, [&](const kestrel::octomap_t& m) {
      if (held_map == std::pair{m.revision, m.utime}) return;
      if (m.size != static_cast<int32_t>(m.data.size())) throw InputError("MAP_OCTOMAP: size disagrees with data");
      const auto tree = mapper::read_octree(
          m.data.data(), m.data.size(),
          m.format == kestrel::octomap_t::FORMAT_BINARY ? mapper::OctreeFormat::kBinary : mapper::OctreeFormat::kFull,
          "MAP_OCTOMAP");
      planner.set_map(project_octomap(*tree, o.map_z_min_m, o.map_z_max_m, "MAP_OCTOMAP"));
      held_map = std::pair{m.revision, m.utime};
      node.set_health(kestrel::process_status_t::STATE_RUNNING, "map revision " + std::to_string(m.revision));
    }, 2);
    node.subscribe<kestrel::state_t>(channel::kState, [&](const kestrel::state_t& s) {
      // An initialising (or awaiting SLAM's world: --await-world) or failed filter's pose is
      // not where the vehicle is.
      if (s.status != kestrel::state_t::STATUS_OK && s.status != kestrel::state_t::STATUS_DEGRADED) return;
      const auto [q, cov] = from_state(s);
      planner.set_state(q, cov);
    });
    node.subscribe<kestrel::plan_request_t>(channel::kPlanRequest, [&](const kestrel::plan_request_t& r) {
      PlanQuery q;
      q.request_id = static_cast<long>(r.request_id);
      if (r.start_mode == kestrel::plan_request_t::START_GIVEN) {
        q.start = Config(r.start[0], r.start[1], r.start[2], r.start[3]);
        q.start_trace = r.start_covariance_trace;
      }
      q.goal = Config(r.goal[0], r.goal[1], r.goal[2], r.goal[3]);
      q.brm = r.planner != kestrel::plan_request_t::PLANNER_PRM;
      if (r.planner == kestrel::plan_request_t::PLANNER_BRM_DOMINANCE) {
        q.pruning = BrmPruning::kCovarianceDominance;
        q.dominance_slack = dominance_slack;
      }
      q.objective = r.objective == kestrel::plan_request_t::OBJECTIVE_SHORTEST_BOUNDED ? BrmObjective::kShortestBounded
                                                                                       : BrmObjective::kMinGoalUncertainty;
      if (r.objective == kestrel::plan_request_t::OBJECTIVE_SHORTEST_BOUNDED) q.max_trace = r.max_covariance_trace;
      const bool known = (r.start_mode == 0 || r.start_mode == 1) && (r.planner >= 0 && r.planner <= 2) &&
                         (r.objective == 0 || r.objective == 1);
      const auto t0 = std::chrono::steady_clock::now();
      PlanAnswer a;
      if (known) a = planner.plan(q);
      else {
        a.status = PlanAnswer::kBadRequest;
        a.message = "unknown start mode, planner or objective";
      }
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
      out.planning_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      node.publish(channel::kPlan, out);
    });
    node.on_reset([&] {
      planner.reset();
      held_map.reset();
    });
    return node.spin();
  });
}
