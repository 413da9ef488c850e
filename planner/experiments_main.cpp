// kestrel-plan-experiments: the paper's planning experiments (§4) in the sim's worlds — the
// shipped `floor` world and `stata` (built from the real Stata basement map when it is
// present) — as Markdown tables with the paper's figures beside ours, and PNG plots of the
// five paths. See planner/README.md.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "planner/eval/plot.h"
#include "planner/eval/tables.h"
#include "planner/experiment_worlds.h"

#ifndef KESTREL_DEFAULT_STATA_MAP
#define KESTREL_DEFAULT_STATA_MAP "../shared/data/maps/stata_basement.yaml"
#endif

namespace {

using namespace kestrel;
using namespace kestrel::planner;

// All five pairs planned by PRM-uniform (red) and BRM-SU (blue) on the first trial's seed,
// with 1-sigma ellipses at the nodes; the samples drawn are BRM-SU's of pair 1.
cv::Mat draw_paths(const ExperimentWorld& w, const planner::eval::Scenario& sc, const planner::eval::ExperimentOptions& o) {
  const FeatureSensor fs(*w.env, sc.sensor);
  const BeliefModel model(sc.motion, [&](const Config& q) { return fs.information(q); });
  std::vector<planner::eval::DrawnPath> drawn;
  std::vector<Config> samples;
  for (size_t p = 0; p < w.pairs.size(); ++p)
    for (const char* planner : {"prm", "brm"}) {
      const bool brm = planner[0] == 'b';
      const planner::eval::Trial t = planner::eval::run_trial(sc, planner::eval::Setting{planner, brm ? "su" : "uniform", o.samples},
                                            w.pairs[p].first, w.pairs[p].second, o.seed * 1000003ull + p * 1009ull);
      drawn.push_back({t.path, planner::eval::node_covariances(t.path, model, sc.start_covariance),
                       brm ? cv::Scalar(200, 0, 0) : cv::Scalar(0, 0, 220)});
      if (brm && p == 0) samples = t.samples;
    }
  const Eigen::AlignedBox3d b = w.env->bounds();
  const double extent = std::max(b.sizes().x(), b.sizes().y());
  return planner::eval::draw_plans(*w.env, samples, drawn, sc.space.z_min_m, std::min(30.0, 2400.0 / extent));
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("plan-experiments",
               "Reproduces the paper's planner tables (BRM vs PRM, samplers) in the sim's floor, atrium and stata worlds");
  planner::eval::ExperimentOptions o;
  std::string only = "all", out_path, which = "all", map_yaml = KESTREL_DEFAULT_STATA_MAP, png_dir;
  WorldFeatureOptions features;
  planner::eval::Scenario base;
  app.add_option("--trials", o.trials, "Trials per start/goal pair and setting")->check(cli::Positive);
  app.add_option("--samples", o.samples, "Samples per roadmap")->check(cli::Positive);
  app.add_option("--seed", o.seed, "Seed of every random draw (features, samplers)");
  app.add_option("--world", which, "floor, atrium, stata or all")
      ->check(CLI::IsMember({"all", "floor", "atrium", "stata"}));
  app.add_option("--map", map_yaml, "ROS map the stata world is built from (skipped with a message when absent)");
  app.add_option("--feature-density", features.mean_density_per_m2,
                 "Mean features per square metre over the walls (each wall's share follows its texture)")
      ->check(cli::Positive);
  app.add_option("--only", only, "One experiment: table3, table4, table5, fig7, fig12, fig13, laser, precision, or all")
      ->check(CLI::IsMember({"all", "table3", "table4", "table5", "fig7", "fig12", "fig13", "laser", "precision"}));
  app.add_option("--radius", base.space.radius_m, "Vehicle radius (m)")->check(cli::Positive);
  app.add_option("--connect-radius", base.roadmap.connect_radius_m,
                 "Longest edge (m; default none: the paper joins every collision-free pair)")
      ->check(cli::Positive);
  app.add_option("--neighbours", base.roadmap.max_neighbours,
                 "Each node tries its nearest this many within the connect radius (0, the default: all)")
      ->check(CLI::NonNegativeNumber);
  std::vector<double> laser_ranges{1.5, 5.0};
  app.add_option("--laser-ranges", laser_ranges, "The laser experiment's short and long range (m)")
      ->expected(2)
      ->check(cli::Positive);
  app.add_option("--out", out_path, "Also write the Markdown to this file");
  app.add_option("--png-dir", png_dir, "Draw <world>_paths.png (PRM red, BRM-SU blue, all five pairs) here");
  return app.run(argc, argv, [&]() -> int {
    features.seed = o.seed;
    // The outputs are checked before the experiments, which take many minutes: a missing
    // --png-dir is made, and what cannot be written is an error now rather than at the end.
    if (!png_dir.empty()) {
      std::error_code ec;
      std::filesystem::create_directories(png_dir, ec);
      if (ec) throw InputError(png_dir + ": cannot make the folder: " + ec.message());
      if (!std::filesystem::is_directory(png_dir) || ::access(png_dir.c_str(), W_OK) != 0)
        throw InputError(png_dir + ": not a writable folder");
    }
    // Each section goes to the file as it is done, so an interrupted run keeps what it made:
    // the file is replaced by all the text so far, atomically, so an earlier result is never cut
    // short in place and a run killed mid-write leaves whole sections only.
    // A device or a FIFO (`--out /dev/stderr`) is a stream: it gets each section once.
    std::error_code ec;
    const bool stream = !out_path.empty() && std::filesystem::exists(out_path, ec) &&
                        !std::filesystem::is_regular_file(out_path, ec);
    std::string written;
    const auto emit = [&](const std::string& text) {
      std::cout << text << std::flush;
      if (out_path.empty()) return;
      written += text;
      write_file_atomically(out_path, stream ? text : written);
    };
    const auto section = [&](const std::string& name, const std::string& title, const auto& body) {
      if (only != "all" && only != name) return;
      spdlog::info("running {}", name);
      emit("### " + title + "\n\n" + body() + "\n");
    };
    emit(std::to_string(o.trials) + " trials per pair and setting, " + std::to_string(o.samples) + " samples, seed " +
         std::to_string(o.seed) + ".\n\n");
    // Table 3 is about the weight's cost per measurement count, not about a world.
    section("table3", "Table 3: cost of the sensor-uncertainty weight per sample",
            [&] { return planner::eval::table3_weight_cost(o.seed); });

    std::vector<ExperimentWorld> worlds;
    if (which == "all" || which == "floor") worlds.push_back(floor_experiment_world(features, base.space.radius_m));
    if (which == "all" || which == "atrium") worlds.push_back(atrium_experiment_world(features, base.space.radius_m));
    if (which == "all" || which == "stata") {
      auto stata = stata_experiment_world(map_yaml, features, base.space.radius_m);
      if (stata) worlds.push_back(std::move(*stata));
      else emit("## World stata\n\nSkipped: the map " + map_yaml + " is absent.\n\n");
    }
    for (const ExperimentWorld& w : worlds) {
      planner::eval::Scenario sc = base;
      sc.env = w.env.get();
      const planner::eval::Pairs pairs(w.pairs.begin(), w.pairs.end());
      const Eigen::AlignedBox3d b = w.env->bounds();
      std::ostringstream head;
      head << std::fixed << std::setprecision(1) << "## World " << w.name << "\n\n" << w.world->source() << ", "
           << b.sizes().x() << " x " << b.sizes().y()
           << " m, " << w.env->features().size() << " wall features (mean " << features.mean_density_per_m2
           << " /m², per-wall share from the textures); pair distances";
      for (const auto& p : pairs) head << " " << (p.second - p.first).head<3>().norm();
      head << " m.\n\n";
      emit(head.str());
      section("table4", "Table 4: BRM success % · final tr(Σ) per sampler and path",
              [&] { return planner::eval::table4_samplers(sc, pairs, o); });
      section("table5", "Table 5: planners and samplers (all five paths)",
              [&] { return planner::eval::table5_planners(sc, pairs, o); });
      section("fig7", "Fig. 7: one-step transfer with the UKF's M vs the full UKF update",
              [&] { return planner::eval::fig7_ukf_transfer(sc, o); });
      section("fig12", "Figs. 12/13: BRM-SU against the number of samples (paper camera)",
              [&] { return planner::eval::fig12_sample_counts(sc, pairs, o, {10, 30, 100, 300, 500}); });
      section("fig13", "Fig. 13: BRM-SU against the number of samples (Kinect model: 4 m, 57 x 43 deg)", [&] {
        planner::eval::Scenario kinect = sc;
        kinect.sensor = FeatureSensorOptions::kinect();
        return planner::eval::fig12_sample_counts(kinect, pairs, o, {10, 30, 100, 300});
      });
      section("laser", "Laser validation: shorter range, longer but localisable paths",
              [&] { return planner::eval::laser_experiment(sc, pairs, o, laser_ranges[0], laser_ranges[1], 1.0); });
      section("precision", "Transfer precision on every roadmap edge (relative tr(Σ) error vs step-by-step EKF)",
              [&] { return planner::eval::transfer_precision(sc, pairs, o); });
      if (!png_dir.empty()) {
        const std::string path = (std::filesystem::path(png_dir) / (w.name + "_paths.png")).string();
        image::write_png(path, draw_paths(w, sc, o));  // atomic: no cut image that looks whole
        spdlog::info("wrote {}", path);
      }
    }
    return kExitOk;
  });
}
