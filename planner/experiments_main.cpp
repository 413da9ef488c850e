// kestrel-plan-experiments: the paper's planning experiments (§4) on the built-in Stata-like
// floor, as Markdown tables with the paper's figures beside ours. See planner/README.md.
#include <spdlog/spdlog.h>

#include <fstream>
#include <iostream>

#include "common/cli.h"
#include "common/error.h"
#include "planner/eval/tables.h"
#include "planner/floor_plan.h"

int main(int argc, char** argv) {
  using namespace kestrel;
  using namespace kestrel::planner;
  cli::App app("plan-experiments", "Reproduces the paper's planner tables (BRM vs PRM, samplers) on a Stata-like floor");
  eval::ExperimentOptions o;
  std::string only = "all", out_path;
  double density = 4.0, wall_piece = 2.0;
  app.add_option("--trials", o.trials, "Trials per start/goal pair and setting")->check(cli::Positive);
  app.add_option("--samples", o.samples, "Samples per roadmap")->check(cli::Positive);
  app.add_option("--seed", o.seed, "Seed of every random draw");
  app.add_option("--feature-density", density, "Features per square metre of textured wall")->check(cli::Positive);
  app.add_option("--wall-piece", wall_piece, "Length (m) of wall sharing one texture density")->check(cli::Positive);
  app.add_option("--only", only, "One experiment: table3, table4, table5, fig7, fig12, laser, precision, or all")
      ->check(CLI::IsMember({"all", "table3", "table4", "table5", "fig7", "fig12", "laser", "precision"}));
  app.add_option("--out", out_path, "Also write the Markdown to this file");
  return app.run(argc, argv, [&]() -> int {
    GridEnvironment env(stata_like_floor(), 0.0, 3.0);
    env.set_features(env.wall_features(density, wall_piece, o.seed));
    eval::Scenario sc;
    sc.env = &env;
    eval::Pairs pairs;
    for (const auto& p : stata_like_pairs()) pairs.push_back(p);
    std::ostringstream md;
    const auto section = [&](const std::string& name, const std::string& title, const auto& body) {
      if (only != "all" && only != name) return;
      spdlog::info("running {}", name);
      const std::string text = "### " + title + "\n\n" + body() + "\n";
      md << text;
      std::cout << text << std::flush;
    };
    md << "Built-in Stata-like floor (13 x 23 m), " << env.features().size() << " wall features, seed " << o.seed
       << ", " << o.trials << " trials, " << o.samples << " samples.\n\n";
    section("table3", "Table 3: cost of the sensor-uncertainty weight per sample",
            [&] { return eval::table3_weight_cost(o.seed); });
    section("table4", "Table 4: BRM success % · final tr(Σ) per sampler and path",
            [&] { return eval::table4_samplers(sc, pairs, o); });
    section("table5", "Table 5: planners and samplers (all five paths)",
            [&] { return eval::table5_planners(sc, pairs, o); });
    section("fig7", "Fig. 7: one-step transfer with the UKF's M vs the full UKF update",
            [&] { return eval::fig7_ukf_transfer(sc, o); });
    section("fig12", "Figs. 12/13: BRM-SU against the number of samples (paper camera)",
            [&] { return eval::fig12_sample_counts(sc, pairs, o, {10, 30, 100, 300, 500}); });
    section("laser", "Laser validation: shorter range, longer but localisable paths",
            [&] { return eval::laser_experiment(sc, pairs, o, 1.5, 5.0, 1.0); });
    section("precision", "Transfer precision on every roadmap edge (relative tr(Σ) error vs step-by-step EKF)",
            [&] { return eval::transfer_precision(sc, pairs, o); });
    if (!out_path.empty()) {
      std::ofstream f(out_path);
      if (!(f << md.str())) throw InputError(out_path + ": cannot write");
    }
    return kExitOk;
  });
}
