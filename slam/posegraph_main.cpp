// kestrel-posegraph: the SLAM pose-graph optimiser on a g2o file (SE2 or SE3).
//
//   kestrel-posegraph FILE.g2o [--out result.g2o] [--kernel cauchy --kernel-width 3]
//
// Prints the graph's size, the chi2 (g2o's convention) before and after, the iterations and
// the solve time (reading and writing excluded). Refuses (exit 3) information matrices that
// are not positive semi-definite unless --repair-information, and values that would overflow
// chi2; says which components it had to anchor (not connected to the fixed vertex); never
// reports a non-finite chi2 as a result.

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "slam/memory_policy.h"
#include "slam/posegraph/g2o_io.h"
#include "slam/posegraph/optimizer.h"

namespace {

using namespace kestrel;
using namespace kestrel::slam;

// "vertex 57 (12 vertices), vertex 90 (1 vertex)": the first few, by the file's ids.
template <class Space>
std::string describe(const PoseGraph<Space>& graph, const std::vector<AnchoredComponent>& components) {
  std::string text;
  const size_t shown = std::min<size_t>(components.size(), 5);
  for (size_t i = 0; i < shown; ++i) {
    const AnchoredComponent& c = components[i];
    text += fmt::format("{}vertex {} ({} {})", i == 0 ? "" : ", ", graph.ids[c.vertex], c.size,
                        c.size == 1 ? "vertex" : "vertices");
  }
  if (shown < components.size()) text += fmt::format(" and {} more", components.size() - shown);
  return text;
}

// The vertex (or vertices) the file anchors: its FIX lines, else the first vertex.
template <class Space>
std::string given_anchor(const PoseGraph<Space>& graph) {
  std::string ids;
  for (int v = 0; v < graph.num_vertices(); ++v)
    if (graph.fixed[v]) ids += (ids.empty() ? "" : ", ") + std::to_string(graph.ids[v]);
  return ids.empty() ? "vertex " + std::to_string(graph.ids[0]) + " (the first; no FIX line)" : "FIX " + ids;
}

template <class Space>
void run(PoseGraph<Space>& graph, const OptimizerOptions& options, const std::string& input,
         const std::string& out) {
  int loops = 0;
  for (const auto& e : graph.edges) loops += e.kind == EdgeKind::kLoopClosure;
  const auto start = std::chrono::steady_clock::now();
  const std::clock_t cpu_start = std::clock();
  const OptimizerSummary s = optimize(graph, options);
  const double cpu_seconds = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // The reader bounds every value so that this cannot happen from a file; were it to, a
  // number printed as the result would be garbage.
  if (!std::isfinite(s.initial_chi2)) throw InputError(input + ": chi2 at the given poses is not finite");
  if (!std::isfinite(s.final_chi2) || !std::isfinite(s.final_cost))
    throw std::runtime_error(input + ": the optimisation ended at a non-finite chi2");
  if (!s.anchored_components.empty()) {
    int vertices = 0;
    for (const AnchoredComponent& c : s.anchored_components) vertices += c.size;
    spdlog::warn("{}: {} vertices in {} parts of the graph are not connected to the anchor ({}): each part was "
                 "held at its first vertex, so only its shape is optimised, not where it lies: {}",
                 input, vertices, s.anchored_components.size(), given_anchor(graph),
                 describe(graph, s.anchored_components));
  }
  fmt::print("space             {}\n", Space::kName);
  fmt::print("vertices          {}\n", graph.num_vertices());
  fmt::print("edges             {} ({} loop closures)\n", graph.num_edges(), loops);
  if (!s.anchored_components.empty()) {
    fmt::print("anchored parts    {} not connected to the anchor, each held at its first vertex: {}\n",
               s.anchored_components.size(), describe(graph, s.anchored_components));
  }
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
  bool repair_information = false;
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
  app.add_flag("--repair-information", repair_information,
               "Replace information matrices that are not positive semi-definite by the nearest ones "
               "(some published graphs hold thousands) instead of refusing the file");
  return app.run(argc, argv, [&] {
    options.chordal_initialization = init == "chordal";
    options.kernel.type = parse_kernel_type(kernel);
    options.on_step = [](const StepLog& l) {
      spdlog::debug("step {:3d}: cost {:.10g} -> {:.10g} (model {:.3g}), lambda {:.1e}, |dx| {:.3g}, {}{}{}",
                    l.iteration, l.cost, l.new_cost, l.predicted, l.lambda, l.step_norm,
                    l.factorized ? "factorised" : fmt::format("{} CG iterations", l.cg_iterations),
                    l.accelerated ? ", accelerated" : "", l.accepted ? "" : ", rejected");
    };
    G2oReadOptions read_options;
    read_options.project_information = repair_information;
    G2oStats stats;
    AnyPoseGraph graph = read_g2o(input, &stats, read_options);
    if (stats.repaired_information > 0) {
      spdlog::warn("{}: {} information matrices were not positive semi-definite and were replaced by the "
                   "nearest ones (--repair-information; the first on line {})",
                   input, stats.repaired_information, stats.first_repaired_line);
    }
    std::visit([&](auto& g) { run(g, options, input, output); }, graph);
    return kExitOk;
  });
}
