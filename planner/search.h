#pragma once
// Searches over a Roadmap: PRM's shortest path, and the Belief Roadmap's search (the paper's
// Algorithm 1) with either objective.
//
// BRM labels are (node, Sigma, path); a label never revisits a node on its own path.
//  * kMinGoalUncertainty — Algorithm 1: a label reaching node n is kept when its tr(Sigma) is
//    below the best seen at n; the goal's best label is the answer. Labels are expanded in
//    order of tr(Sigma) (the paper uses FIFO) and skipped once superseded at their node.
//  * kShortestBounded — shortest path with tr(Sigma) < max_trace at every node: labels in order
//    of length, dropped when over the bound or dominated at their node by a label that is both
//    shorter and better localised (tr). The bound is checked at nodes, as in the paper,
//    and along edges too when the query gives `edge_peak_trace`.

#include <functional>
#include <limits>
#include <vector>

#include "planner/roadmap.h"

namespace kestrel::planner {

enum class BrmObjective { kMinGoalUncertainty, kShortestBounded };

struct PlanResult {
  bool found = false;
  std::vector<int> nodes;          ///< start ... goal
  std::vector<double> traces;      ///< predicted tr(Sigma) at each node (empty for PRM)
  double length_m = 0.0;
  Mat4 goal_covariance = Mat4::Zero();
  long expansions = 0;             ///< labels expanded
};

/// Dijkstra on edge length.
PlanResult shortest_path(const Roadmap& map, int start, int goal);

struct BrmQuery {
  Mat4 start_covariance = Mat4::Identity();
  BrmObjective objective = BrmObjective::kMinGoalUncertainty;
  double max_trace = std::numeric_limits<double>::infinity();
  /// Unset: max_trace is checked at nodes only (the paper's Algorithm 1). Set: also along
  /// each edge, from -> to entered with `sigma`: it returns the largest tr(Sigma) on the way
  /// (e.g. peak_trace_along with the roadmap's BeliefModel), and a label whose edge peaks at
  /// or over max_trace is dropped. Called only for labels that pass every other test.
  std::function<double(int from, int to, const Mat4& sigma)> edge_peak_trace;
};

PlanResult belief_search(const Roadmap& map, int start, int goal, const BrmQuery& query);

/// tr(Sigma) at each node of `nodes` flown from `start_covariance` (fills traces and
/// goal_covariance of a PRM result). Throws std::invalid_argument if two nodes are not joined.
void predict_along(const Roadmap& map, const Mat4& start_covariance, PlanResult& path);

}  // namespace kestrel::planner
