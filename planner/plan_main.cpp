// kestrel-plan: plans offline in a world (the sim's `floor`, any .world file) or on a ROS map
// yaml with BRM or PRM, prints the waypoints with their predicted tr(Sigma), and optionally draws them.
// See planner/README.md.
#include <spdlog/spdlog.h>

#include <iostream>

#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "drivers/sim/world_catalog.h"
#include "planner/eval/experiment.h"
#include "planner/eval/plot.h"
#include "planner/map_sources.h"
#include "planner/samplers.h"
#include "planner/world_environment.h"

namespace {

using namespace kestrel;
using namespace kestrel::planner;

Config to_config(const std::vector<double>& v) { return Config(v[0], v[1], v[2], v[3]); }

}  // namespace

int main(int argc, char** argv) {
  cli::App app("plan", "Plans a well-localised path offline (Belief Roadmap, or PRM for comparison)");
  std::string map = "floor", planner = "brm", sampler = "su", sensor = "camera", png;
  std::vector<double> start{2.5, 2.5, 1.0, 0.0}, goal{10.5, 20.0, 1.0, 0.0};
  planner::eval::Scenario sc;
  int samples = 300;  // more than the paper's 100: BRM finds better-localised paths with more
  sc.roadmap = RoadmapOptions{};  // 6 m / 20 neighbours: the grown roadmap reaches 3000 samples
  sc.roadmap.max_samples = 3000;
  uint64_t seed = 1;
  double density = 4.0, laser_range = 5.0, z_max = 3.0, start_trace = 0.4;
  double dominance_slack = kToolsDominanceSlack;
  // Which map is a question of the command line (exit 2); what a world or map file holds is
  // input, checked as it is read (exit 3). The sim's stata world is extruded from a ROS map,
  // which this tool plans on as it is.
  app.add_option("--map", map,
                 "A sim world (built in: room, floor, office, atrium; or a .world file) or a ROS map YAML")
      ->check(CLI::Validator(
          [](std::string& what) {
            if (what == "stata") return std::string("the stata world is a ROS map: give its .yaml as --map");
            return sim::unknown_world_error(what, /*with_stata=*/false);
          },
          ""));
  app.add_option("--start", start, "Start x y z yaw (m, rad)")->expected(4);
  app.add_option("--goal", goal, "Goal x y z yaw (m, rad)")->expected(4);
  app.add_option("--planner", planner,
                 "brm (Algorithm 1), brm-dominance (keeps every label no covariance beats: slower, better localised) "
                 "or prm")
      ->check(CLI::IsMember({"brm", "brm-dominance", "prm"}));
  app.add_option("--dominance-slack", dominance_slack,
                 "brm-dominance: drop a label within this fraction of a kept one (0: exact, can take minutes)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--sampler", sampler, "uniform, su, gaussian, bridge, su-ukf")
      ->check(CLI::IsMember(planner::sampler_names()));
  app.add_option("--sensor", sensor, "camera (the paper's), kinect, laser")->check(CLI::IsMember({"camera", "kinect", "laser"}));
  app.add_option("--laser-range", laser_range, "Laser range (m)")->check(cli::Positive);
  app.add_option("--samples", samples, "Roadmap samples (drawn again while start and goal are not connected)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--max-samples", sc.roadmap.max_samples, "Most samples the roadmap grows to (<= --samples: no growth)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--seed", seed, "Seed of the sampler and the features");
  app.add_option("--radius", sc.space.radius_m, "Vehicle radius (m)")->check(cli::Positive);
  app.add_option("--height", sc.space.z_min_m, "Flight height (m)")->check(cli::Positive);
  app.add_option("--ceiling", z_max, "Height of the walls the map is extruded to (m)")->check(cli::Positive);
  app.add_option("--feature-density", density, "Features per square metre of textured wall")->check(cli::Positive);
  app.add_option("--connect-radius", sc.roadmap.connect_radius_m, "Longest edge (m)")->check(cli::Positive);
  app.add_option("--start-trace", start_trace, "tr(Sigma) at the start (m^2, spread evenly)")->check(cli::Positive);
  app.add_option("--png", png, "Draw the map, samples, path and covariance ellipses to this PNG");
  return app.run(argc, argv, [&]() -> int {
    sc.space.z_max_m = sc.space.z_min_m;
    sc.start_covariance = (start_trace / 4.0) * Mat4::Identity();
    // Sim worlds through the sim's own loader (features from their textures); maps as grids.
    const bool is_map = map.size() > 5 && map.substr(map.size() - 5) == ".yaml";
    std::unique_ptr<sim::World> world;
    std::unique_ptr<Environment> environment;
    if (is_map) {
      auto grid = std::make_unique<GridEnvironment>(read_ros_map(map), 0.0, z_max);
      grid->set_features(grid->wall_features(density, 2.0, seed));
      environment = std::move(grid);
    } else {
      world = std::make_unique<sim::World>(sim::load_world(map));
      auto w = std::make_unique<WorldEnvironment>(*world);
      w->place_features({density, seed});
      environment = std::move(w);
    }
    const Environment& env = *environment;
    sc.env = &env;
    sc.sensor = sensor == "camera" ? FeatureSensorOptions::paper_camera()
                : sensor == "kinect" ? FeatureSensorOptions::kinect()
                                     : FeatureSensorOptions::planar_laser(laser_range);
    const Config q0 = to_config(start), q1 = to_config(goal);
    const ConfigurationSpace space(env, sc.space);
    if (!space.is_valid(q0)) throw CLI::ValidationError("--start", "start is not in free space");
    if (!space.is_valid(q1)) throw CLI::ValidationError("--goal", "goal is not in free space");
    const planner::eval::Trial t = planner::eval::run_trial(sc, planner::eval::Setting{planner, sampler, samples, dominance_slack}, q0, q1, seed);
    spdlog::info("{} features, build {:.3f} s, search {:.2f} ms", env.features().size(), t.build_s, 1e3 * t.search_s);
    if (!t.found) {
      std::cerr << "kestrel-plan: no path found with " << t.samples.size() << " samples\n";
      return kExitFailure;
    }
    // Covariances at the waypoints, flown step by step with the same models.
    const FeatureSensor fs(env, sc.sensor);
    const BeliefModel model(sc.motion, [&](const Config& q) { return fs.information(q); });
    std::vector<Mat4> covariances{sc.start_covariance};
    for (size_t i = 1; i < t.path.size(); ++i)
      covariances.push_back(propagate_ekf(covariances.back(), model.steps(t.path[i - 1], t.path[i])));
    std::cout << "# x y z yaw tr(Sigma)   length " << t.length_m << " m, goal tr(Sigma) " << t.goal_trace << "\n";
    for (size_t i = 0; i < t.path.size(); ++i)
      std::cout << t.path[i][0] << " " << t.path[i][1] << " " << t.path[i][2] << " " << t.path[i][3] << " "
                << covariances[i].trace() << "\n";
    if (!png.empty()) {
      planner::eval::DrawnPath drawn{t.path, covariances, planner != "prm" ? cv::Scalar(200, 0, 0) : cv::Scalar(0, 0, 220)};
      // Atomic: no cut image that looks whole.
      image::write_png(png, planner::eval::draw_plans(env, t.samples, {drawn}, sc.space.z_min_m));
    }
    return kExitOk;
  });
}
