// kestrel-plan-experiments: the paper's planning experiments (§4) on the built-in Stata-like
// floor, as Markdown tables with the paper's figures beside ours. See planner/README.md.
#include <spdlog/spdlog.h>

#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "common/cli.h"
#include "common/error.h"
#include "planner/eval/plot.h"
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
  app.add_option("--only", only, "One experiment: table3, table4, table5, fig7, fig12, fig13, laser, precision, or all")
      ->check(CLI::IsMember({"all", "table3", "table4", "table5", "fig7", "fig12", "fig13", "laser", "precision"}));
  app.add_option("--out", out_path, "Also write the Markdown to this file");
  std::string png_path;
  app.add_option("--png", png_path, "Draw path 1 planned by PRM (red) and BRM-SU (blue) to this PNG");
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
    section("fig13", "Fig. 13: BRM-SU against the number of samples (Kinect model: 4 m, 57 x 43 deg)", [&] {
      eval::Scenario kinect = sc;
      kinect.sensor = FeatureSensorOptions::kinect();
      return eval::fig12_sample_counts(kinect, pairs, o, {10, 30, 100, 300});
    });
    section("laser", "Laser validation: shorter range, longer but localisable paths",
            [&] { return eval::laser_experiment(sc, pairs, o, 1.5, 5.0, 1.0); });
    section("precision", "Transfer precision on every roadmap edge (relative tr(Σ) error vs step-by-step EKF)",
            [&] { return eval::transfer_precision(sc, pairs, o); });
    if (!png_path.empty()) {
      // Path 1: PRM (red) and BRM-SU (blue) on the same seed, with covariance ellipses.
      const FeatureSensor fs(env, sc.sensor);
      const BeliefModel model(sc.motion, [&](const Config& q) { return fs.information(q); });
      std::vector<eval::DrawnPath> drawn;
      std::vector<Config> samples;
      for (const char* planner : {"prm", "brm"}) {
        const eval::Trial t = eval::run_trial(sc, eval::Setting{planner, planner[0] == 'b' ? "su" : "uniform", o.samples},
                                              pairs[0].first, pairs[0].second, o.seed);
        std::vector<Mat4> cov{sc.start_covariance};
        for (size_t i = 1; i < t.path.size(); ++i)
          cov.push_back(propagate_ekf(cov.back(), model.steps(t.path[i - 1], t.path[i])));
        drawn.push_back({t.path, cov, planner[0] == 'b' ? cv::Scalar(200, 0, 0) : cv::Scalar(0, 0, 220)});
        if (planner[0] == 'b') samples = t.samples;
      }
      if (!cv::imwrite(png_path, eval::draw_plans(env, samples, drawn))) throw InputError(png_path + ": cannot write");
    }
    if (!out_path.empty()) {
      std::ofstream f(out_path);
      if (!(f << md.str())) throw InputError(out_path + ": cannot write");
    }
    return kExitOk;
  });
}
