// kestrel-fly-plans: the paper's planning flights (Figs. 15-17) in closed loop. In each world,
// for each start/goal pair of the planning experiments, plans with PRM (the shortest path) and
// BRM-SU (the best-localised one) on the world itself, then flies each plan with the whole
// system in the loop (closed_loop.h), several seeds each, and scores every flight against the
// truth (flight_score.h). Writes the tables (report.md), every figure (flights.json) and a
// picture per pair: the map, the planned paths with the belief model's 1-sigma ellipses, and
// the flown tracks coloured by the estimator's true error. See README.md.

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "common/interrupt.h"
#include "common/transport/lcm_url.h"
#include "planner/eval/experiment.h"
#include "planner/eval/plot.h"
#include "planner/experiment_worlds.h"
#include "planner/samplers.h"
#include "tools/flights/closed_loop.h"
#include "tools/flights/flight_log.h"
#include "tools/flights/flight_report.h"
#include "drivers/sim/world_catalog.h"
#include "vo/option_keys.h"

#ifndef KESTREL_DEFAULT_STATA_MAP
#define KESTREL_DEFAULT_STATA_MAP "../shared/data/maps/stata_basement.yaml"
#endif

namespace {

using namespace kestrel;
namespace fs = std::filesystem;

struct Options {
  std::vector<std::string> worlds{"stata"};
  std::string map = KESTREL_DEFAULT_STATA_MAP;
  std::vector<int> pairs;  // 1-based; empty: all
  std::vector<double> start, goal;  // one pair of the user's instead of the experiment's
  std::vector<std::string> planners{"prm:uniform", "brm:su"};
  int samples = 100;
  int max_samples = 1000;
  int seeds = 3;
  uint64_t first_seed = 1;
  std::string sensor = "kinect";
  double max_trace = 1.0;
  double speed = 0.5;
  double arrive_radius = 0.3;
  double ack_timeout = 60.0;
  std::string out = "fly-plans-output";
  bool plan_only = false;
  std::string lcm_url;
  std::vector<std::string> vo_settings;  // kestrel-vo --set KEY=VALUE
};

struct PlannedFlight {
  std::string name;  // "brm-su"
  planner::eval::Trial trial;
  std::vector<planner::Mat4> covariances;  // the belief model's, at the nodes
};

// The experiment's worlds come with their pairs; any other sim world (room, office, a .world
// file) is flown between --start and --goal, which also replace an experiment world's pairs.
std::optional<planner::ExperimentWorld> load(const std::string& name, const Options& o,
                                             const planner::WorldFeatureOptions& features, double radius) {
  std::vector<std::pair<planner::Config, planner::Config>> pairs;
  if (!o.start.empty())
    pairs.push_back({planner::Config(o.start[0], o.start[1], o.start[2], o.start[3]),
                     planner::Config(o.goal[0], o.goal[1], o.goal[2], o.goal[3])});
  std::optional<planner::ExperimentWorld> w;
  try {
    if (name == "floor") {
      w = planner::floor_experiment_world(features, radius);
    } else if (name == "atrium") {
      w = planner::atrium_experiment_world(features, radius);
    } else if (name == "stata") {
      w = planner::stata_experiment_world(o.map, features, radius);
      if (!w) throw InputError(o.map + ": the stata world's map is not there (--map)");
    } else {
      if (pairs.empty()) throw CLI::ValidationError("--start", "world '" + name + "' has no experiment pairs: give --start and --goal");
      return planner::make_experiment_world(name, sim::load_world(name, ""), features, pairs, radius);
    }
    if (!pairs.empty()) return planner::make_experiment_world(name, std::move(*w->world), features, pairs, radius);
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const InputError*>(&e) || dynamic_cast<const CLI::Error*>(&e)) throw;
    throw CLI::ValidationError("--start", e.what());  // a start or goal that is not free
  }
  return w;
}

std::vector<Eigen::Vector4d> as_waypoints(const std::vector<planner::Config>& path) {
  return {path.begin(), path.end()};
}

int run(const Options& o) {
  planner::eval::Scenario base;
  base.roadmap.max_samples = o.max_samples;
  base.sensor = o.sensor == "kinect" ? planner::FeatureSensorOptions::kinect() : planner::FeatureSensorOptions::paper_camera();
  planner::WorldFeatureOptions features;
  features.seed = o.first_seed;
  // The worlds first: a bad world, pair or map is said before anything is set up.
  std::vector<planner::ExperimentWorld> worlds;
  for (const std::string& name : o.worlds) {
    worlds.push_back(std::move(*load(name, o, features, base.space.radius_m)));
    for (int pair : o.pairs)
      if (pair < 1 || pair > static_cast<int>(worlds.back().pairs.size()))
        throw CLI::ValidationError("--pairs", fmt::format("{} has pairs 1 to {}", name, worlds.back().pairs.size()));
  }
  // Before any thread: every flight's processes share this private network, and nothing leaves the host.
  if (!o.plan_only) flights::enter_flight_network("fly-plans");
  const auto& interrupted = catch_interrupts();
  const std::string url = transport::resolve_lcm_url(o.lcm_url);
  const fs::path tool_dir = fs::canonical("/proc/self/exe").parent_path();
  const fs::path out = flights::make_output_folder(o.out);

  std::vector<flights::FlightRow> rows;
  std::string report = "# Closed-loop flights of PRM and BRM plans (kestrel fly-plans)\n\n";
  report += fmt::format("{} seed(s) per plan from seed {}, {} samples per roadmap, the {} sensor model, cruise {} m/s, "
                        "arrived within {} m of the goal by the truth.\n\n",
                        o.seeds, o.first_seed, o.samples, o.sensor, o.speed, o.arrive_radius);
  if (!o.vo_settings.empty()) report += fmt::format("The VO with `--set {}`.\n\n", fmt::join(o.vo_settings, " --set "));
  bool failures = false;
  for (const planner::ExperimentWorld& w : worlds) {
    const planner::ExperimentWorld* world = &w;
    const std::string& world_name = w.name;
    planner::eval::Scenario sc = base;
    sc.env = world->env.get();
    const planner::FeatureSensor sensor(*sc.env, sc.sensor);
    const planner::BeliefModel model(sc.motion, [&sensor](const planner::Config& q) { return sensor.information(q); });
    std::vector<int> pairs = o.pairs;
    if (pairs.empty())
      for (size_t i = 1; i <= world->pairs.size(); ++i) pairs.push_back(static_cast<int>(i));
    for (int pair : pairs) {
      const auto& [start, goal] = world->pairs[static_cast<size_t>(pair - 1)];
      std::vector<PlannedFlight> plans;
      std::vector<planner::eval::DrawnTrack> tracks;
      for (const std::string& spec : o.planners) {
        const auto colon = spec.find(':');
        planner::eval::Setting setting{spec.substr(0, colon), spec.substr(colon + 1), o.samples};
        setting.max_trace = o.max_trace;
        PlannedFlight plan{setting.planner + "-" + setting.sampler, {}, {}};
        plan.trial = planner::eval::run_trial(sc, setting, start, goal, o.first_seed * 1000003ull + static_cast<uint64_t>(pair) * 1009ull);
        if (plan.trial.found) plan.covariances = planner::eval::node_covariances(plan.trial.path, model, sc.start_covariance);
        flights::PlannedPath planned;
        double max_trace = 0.0;
        for (size_t i = 0; i < plan.trial.path.size(); ++i) {
          planned.nodes.push_back(planner::position(plan.trial.path[i]));
          planned.predicted_trace.push_back(plan.covariances[i].topLeftCorner<3, 3>().trace());
          max_trace = std::max(max_trace, planned.predicted_trace.back());
        }
        if (o.plan_only) {
          std::cout << fmt::format("{} pair {} {}: {}", world_name, pair, plan.name,
                                   plan.trial.found ? fmt::format("{:.1f} m, {} nodes, predicted position tr(Sigma) at the goal {:.5f} m², largest {:.5f} m²",
                                                                  plan.trial.length_m, plan.trial.path.size(),
                                                                  planned.predicted_trace.back(), max_trace)
                                                    : std::string("no path"))
                    << std::endl;
          plans.push_back(std::move(plan));
          continue;
        }
        for (int k = 0; k < o.seeds; ++k) {
          if (interrupted) return kExitInterrupted;
          flights::FlightRow row;
          row.world = world_name;
          row.pair = pair;
          row.planner = plan.name;
          row.seed = o.first_seed + static_cast<uint64_t>(k);
          row.planned = plan.trial.found;
          if (!row.planned) {
            spdlog::warn("{} pair {}: {} found no path", world_name, pair, plan.name);
            rows.push_back(row);
            break;
          }
          row.path_length_m = plan.trial.length_m;
          row.predicted_goal_trace = planned.predicted_trace.back();
          row.predicted_max_trace = max_trace;
          flights::FlightSetup setup;
          setup.world = world_name;
          if (world_name == "stata") setup.map = o.map;
          setup.start = start;
          setup.waypoints = as_waypoints(plan.trial.path);
          setup.seed = row.seed;
          setup.speed_m_s = o.speed;
          setup.duration_s = flights::flight_duration_s(setup.waypoints, o.speed);
          setup.ack_timeout_s = o.ack_timeout;
          setup.vo_settings = o.vo_settings;
          setup.dir = out / world_name / fmt::format("pair{}", pair) / plan.name / fmt::format("seed{}", row.seed);
          spdlog::info("{} pair {}: flying {} ({:.1f} m, {:.0f} s of flight), seed {}", world_name, pair, plan.name,
                       row.path_length_m, setup.duration_s, row.seed);
          const flights::FlightRun flown = flights::fly(setup, tool_dir, url, [&] { return interrupted.load(); });
          row.contacts = flown.contacts;
          if (!flown.ok) {
            if (interrupted) return kExitInterrupted;
            row.failure = flown.failure;
            failures = true;
            spdlog::error("{} pair {} {} seed {}: {}", world_name, pair, plan.name, row.seed, flown.failure);
            rows.push_back(row);
            continue;
          }
          const flights::FlightRecord record = flights::read_flight_log(flown.recording.string());
          row.score = flights::score_flight(record, planner::position(goal), o.arrive_radius, planned);
          row.flown = true;
          row.counts = record;
          row.counts.truth.clear();
          row.counts.states.clear();
          spdlog::info("  {} {:.2f} m from the goal; true error mean {:.3f} m, max {:.3f} m; NEES {:.1f}; "
                       "VO {} failed, {} gross of {}; {} loops; {} contacts",
                       row.score.arrived ? "arrived," : "did not arrive,", row.score.final_distance_m,
                       row.score.error_mean_m, row.score.error_max_m, row.score.nees_mean, record.vo_failures,
                       record.vo_gross, record.vo_frames, record.loop_closures, row.contacts);
          if (k == 0) {
            planner::eval::DrawnTrack track;
            for (size_t i = 0; i < row.score.errors_m.size(); i += 10) {
              const int64_t t = row.score.error_utimes[i];
              const auto it = std::lower_bound(record.truth.begin(), record.truth.end(), t,
                                               [](const flights::TruthSample& a, int64_t u) { return a.utime < u; });
              if (it == record.truth.end()) break;
              track.points.push_back(it->p);
              track.values.push_back(row.score.errors_m[i]);
            }
            track.full_scale = 0.3;
            track.thickness = 3;
            tracks.push_back(std::move(track));
          }
          rows.push_back(std::move(row));
        }
        plans.push_back(std::move(plan));
      }
      // The pair's picture: planned paths (PRM red, BRM blue, with the belief model's 1-sigma
      // ellipses) over the first seed's flown tracks (green 0 -> red 0.3 m true error).
      std::vector<planner::eval::DrawnPath> drawn;
      for (const PlannedFlight& p : plans)
        if (p.trial.found)
          drawn.push_back({p.trial.path, p.covariances, p.name.rfind("prm", 0) == 0 ? cv::Scalar(0, 0, 220) : cv::Scalar(200, 0, 0)});
      // The pair's part of the world, 3 m round the plans and the tracks, at 40 px/m.
      std::vector<Eigen::Vector3d> shown;
      for (const auto& d : drawn)
        for (const planner::Config& q : d.nodes) shown.push_back(planner::position(q));
      for (const auto& t : tracks) shown.insert(shown.end(), t.points.begin(), t.points.end());
      const double ppm = 40.0;
      const fs::path png = out / fmt::format("{}_pair{}.png", world_name, pair);
      image::write_png(png.string(), planner::eval::crop_to(planner::eval::draw_plans(*sc.env, {}, drawn, start[2], ppm, tracks),
                                                            *sc.env, shown, 3.0, ppm));
      spdlog::info("wrote {}", png.string());
    }
    report += "## " + world_name + "\n\n" + flights::markdown_table(rows, world_name, o.arrive_radius) + "\n";
    write_file_atomically((out / "report.md").string(), report);
    write_file_atomically((out / "flights.json").string(), flights::to_json(rows).dump(2) + "\n");
  }
  std::cout << report;
  return failures ? kExitFailure : kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("fly-plans",
               "The paper's planning flights in closed loop: PRM and BRM plans flown by the simulated vehicle with "
               "the VO, estimator, SLAM, mapper and follower in the loop, scored against the truth");
  Options o;
  app.add_option("--world", o.worlds,
                 "stata, floor, atrium (the experiment's pairs), or any sim world with --start/--goal (a,b)")
      ->delimiter(',')
      ->check(CLI::Validator([](std::string& w) { return w == "stata" ? std::string() : sim::unknown_world_error(w); }, ""))
      ->capture_default_str();
  auto* start = app.add_option("--start", o.start, "Fly one pair of your own: start x,y,z,yaw (m, rad)")->expected(4)->delimiter(',');
  auto* goal = app.add_option("--goal", o.goal, "... and its goal x,y,z,yaw")->expected(4)->delimiter(',');
  start->needs(goal);
  goal->needs(start);
  app.add_option("--map", o.map, "The ROS map the stata world is built from")->capture_default_str();
  app.add_option("--pairs", o.pairs, "Start/goal pairs of the experiment to fly, 1-based (a,b; default all)")->delimiter(',');
  app.add_option("--planners", o.planners, "planner:sampler settings (prm, brm, brm-dominance; uniform, su, su-ukf, gaussian, bridge)")
      ->delimiter(',')
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            const auto colon = s.find(':');
            if (colon == std::string::npos) return "expected planner:sampler, e.g. brm:su";
            const std::string p = s.substr(0, colon), q = s.substr(colon + 1);
            if (p != "prm" && p != "brm" && p != "brm-dominance") return "unknown planner '" + p + "'";
            const auto names = planner::sampler_names();
            if (std::find(names.begin(), names.end(), q) == names.end()) return "unknown sampler '" + q + "'";
            return "";
          },
          "PLANNER:SAMPLER"))
      ->capture_default_str();
  app.add_option("--samples", o.samples, "Samples per roadmap (the paper's 100)")->check(cli::Positive)->capture_default_str();
  app.add_option("--max-samples", o.max_samples,
                 "While start and goal are not joined, --samples more, up to this many (a path to fly is needed)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--seeds", o.seeds, "Flights per plan, each with its own sensor noise and wind")->check(cli::Positive)->capture_default_str();
  app.add_option("--seed", o.first_seed, "The first flight's seed (and the plans' and features')")->capture_default_str();
  app.add_option("--sensor", o.sensor, "The belief model's sensor: kinect (the flown camera) or camera (the paper's)")
      ->check(CLI::IsMember({"kinect", "camera"}))
      ->capture_default_str();
  app.add_option("--max-trace", o.max_trace,
                 "BRM: the shortest path whose tr(Sigma) (x, y, z, yaw) stays below this at every node; 0: the least "
                 "uncertain goal, however long the way")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--speed", o.speed, "The follower's cruise speed (m/s)")->check(cli::Positive)->capture_default_str();
  app.add_option("--arrive-radius", o.arrive_radius, "Arrived: the true end this close to the goal (m)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--ack-timeout", o.ack_timeout, "Lock-step: the longest wait for a process (s)")->check(cli::Positive)->capture_default_str();
  app.add_option("--out", o.out, "Folder for report.md, flights.json, the pictures and each flight's logs")->capture_default_str();
  app.add_flag("--plan-only", o.plan_only, "Plan and draw each pair's plans, fly nothing");
  app.add_option("--vo-set", o.vo_settings,
                 "KEY=VALUE: a kestrel-vo option for every flight (repeatable; keys: kestrel-vo --print-config)")
      ->each([](const std::string& kv) {
        // Checked here, not by the first flight's VO dying: a bad key or value is a usage error.
        vo::VoOptions check;
        try {
          vo::set_option_assignment(check, kv);
        } catch (const std::invalid_argument& e) {
          throw CLI::ValidationError(e.what());
        }
      });
  app.add_option("--lcm-url", o.lcm_url, "LCM URL inside the private network (default: $LCM_DEFAULT_URL or kestrel's)");
  return app.run(argc, argv, [&] { return run(o); });
}
