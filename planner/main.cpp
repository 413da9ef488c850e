// kestrel-planner: the planning process. MAP_OCTOMAP (projected over the flight band),
// STATE and PLAN_REQUEST in, PLAN out; the work is OnlinePlanner's. See planner/README.md.
#include <spdlog/spdlog.h>

#include <chrono>
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
#include "planner/online_planner.h"
#include "planner/planner_messages.h"
#include "planner/samplers.h"

using namespace kestrel;
using namespace kestrel::planner;

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
  app.add_option("--sampler", o.sampler, "uniform, su, gaussian, bridge, su-ukf (planner/README.md)")
      ->check(CLI::IsMember(planner::sampler_names()));
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
    node.advertise(channel::kPlanCovariance);
    node.set_health(kestrel::process_status_t::STATE_DEGRADED, "no map yet");
    // The mapper sends its last map again while it has no new one (for a planner started since):
    // the one held already is not projected again.
    std::optional<std::pair<int64_t, int64_t>> held_map;  // revision, utime
    node.subscribe<kestrel::octomap_t>(channel::kMapOctomap, [&](const kestrel::octomap_t& m) {
      if (held_map == std::pair{m.revision, m.utime}) return;
      planner.set_map(map_from_message(m, o.map_z_min_m, o.map_z_max_m));
      held_map = std::pair{m.revision, m.utime};
      node.set_health(kestrel::process_status_t::STATE_RUNNING, "map revision " + std::to_string(m.revision));
    }, 2);
    node.subscribe<kestrel::state_t>(channel::kState, [&](const kestrel::state_t& s) {
      // An initialising (or awaiting SLAM's world: --await-world) or failed filter's pose is
      // not where the vehicle is.
      if (s.status != kestrel::state_t::STATUS_OK && s.status != kestrel::state_t::STATUS_DEGRADED) return;
      const auto [q, cov] = state_from_message(s);
      planner.set_state(q, cov);
    });
    node.subscribe<kestrel::plan_request_t>(channel::kPlanRequest, [&](const kestrel::plan_request_t& r) {
      // A request the planner cannot take is answered (the requester waits for a PLAN) and
      // then refused, so that the Node counts it and the health says why.
      PlanQuery q;
      try {
        q = query_from_message(r, dominance_slack);
      } catch (const InputError& e) {
        PlanAnswer refused;
        refused.status = PlanAnswer::kBadRequest;
        refused.message = e.what();
        node.publish(channel::kPlan, plan_message(r, refused, 0.0));
        throw;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const PlanAnswer a = planner.plan(q);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      const kestrel::plan_t plan = plan_message(r, a, ms);
      node.publish(channel::kPlan, plan);
      if (const auto covariance = plan_covariance_message(plan, a)) node.publish(channel::kPlanCovariance, *covariance);
    });
    node.on_reset([&] {
      planner.reset();
      held_map.reset();
    });
    return node.spin();
  });
}
