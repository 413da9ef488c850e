// kestrel-posegraph: the SLAM pose-graph optimiser on a g2o file (SE2 or SE3).
//
//   kestrel-posegraph FILE.g2o [--out result.g2o] [--kernel cauchy --kernel-width 3]
//
// Prints the graph's size, the chi2 (g2o's convention) before and after, the iterations and
// the solve time (reading and writing excluded).

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <variant>

#include "common/cli.h"
#include "common/error.h"
#include "slam/memory_policy.h"
#include "slam/posegraph/g2o_io.h"
#include "slam/posegraph/optimizer.h"

namespace {

using namespace kestrel;
using namespace kestrel::slam;

template <class Space>
void run(PoseGraph<Space>& graph, const OptimizerOptions& options, const std::string& out) {
  int loops = 0;
  for (const auto& e : graph.edges) loops += e.kind == EdgeKind::kLoopClosure;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const OptimizerSummary s = optimize(graph, options);
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("space             {}\n", Space::kName);
  fmt::print("vertices          {}\n", graph.num_vertices());
  fmt::print("edges             {} ({} loop closures)\n", graph.num_edges(), loops);
  fmt::print("initial chi2      {:.10g}\n", s.initial_chi2);
  fmt::print("start chi2        {:.10g} ({})\n", s.start_chi2,
             s.used_chordal ? "chordal initialisation" : "given poses");
  fmt::print("final chi2        {:.10g}\n", s.final_chi2);
  if (options.kernel.type != KernelType::kNone) {
    fmt::print("final robust cost {:.10g} ({} loop closures down-weighted)\n", s.final_cost,
               s.downweighted_edges);
  }
  fmt::print("iterations        {} ({} accepted, {} factorisations, {} CG iterations; stop: {})\n",
             s.iterations, s.accepted, s.factorizations, s.cg_iterations, stop_reason_name(s.stop));
  fmt::print("time              {:.4f} s ({:.4f} s of processor time)\n", seconds, cpu_seconds);
  if (!out.empty()) write_g2o(out, graph);
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::slam::keep_freed_memory();
  cli::App app("posegraph",
               "Optimise a pose graph in g2o format (SE2 or SE3) with kestrel's SLAM optimiser");
  std::string input, output;
  std::string init = "chordal";
  std::string kernel = "none";
  OptimizerOptions options;
  app.add_option("file", input, "The g2o file")->required();
  app.add_option("--out", output, "Write the optimised graph here (g2o)");
  app.add_option("--init", init, "Starting point: chordal (rotation-first, kept if better) or given")
      ->check(CLI::IsMember({"chordal", "given"}))
      ->capture_default_str();
  app.add_option("--max-iterations", options.max_iterations, "Levenberg-Marquardt iterations at most")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--function-tolerance", options.function_tolerance,
                 "Stop when a step lowers the cost by less than this fraction")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--initial-lambda", options.initial_lambda,
                 "Initial Levenberg-Marquardt damping, relative to the diagonal")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--kernel", kernel, "Robust kernel on loop closures: none, huber, cauchy or dcs")
      ->check(CLI::IsMember({"none", "huber", "cauchy", "dcs"}))
      ->capture_default_str();
  app.add_option("--kernel-width", options.kernel.width,
                 "Kernel width, in standard deviations of the edge error")
      ->check(cli::Positive)
      ->capture_default_str();
  return app.run(argc, argv, [&] {
    options.chordal_initialization = init == "chordal";
    options.kernel.type = parse_kernel_type(kernel);
    options.on_step = [](const StepLog& l) {
      spdlog::debug("step {:3d}: cost {:.10g} -> {:.10g} (model {:.3g}), lambda {:.1e}, |dx| {:.3g}, {}{}{}",
                    l.iteration, l.cost, l.new_cost, l.predicted, l.lambda, l.step_norm,
                    l.factorized ? "factorised" : fmt::format("{} CG iterations", l.cg_iterations),
                    l.accelerated ? ", accelerated" : "", l.accepted ? "" : ", rejected");
    };
    AnyPoseGraph graph = read_g2o(input);
    std::visit([&](auto& g) { run(g, options, output); }, graph);
    return kExitOk;
  });
}
