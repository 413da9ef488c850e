// PRM Dijkstra and the BRM label search.
#include "planner/search.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <queue>
#include <stdexcept>

namespace kestrel::planner {
namespace {

struct Label {
  int node;
  int parent;  // index into the label store, -1 for the root
  double length;
  Mat4 sigma;
  double trace;
  bool superseded;  // another label at its node beats it: never expanded
};

// a <= b in the Loewner order (b - a positive semi-definite), to rounding: every direction's
// variance under a is at most b's.
bool loewner_leq(const Mat4& a, const Mat4& b) {
  const Mat4 d = b - a;
  const double tolerance = 1e-12 * std::max(a.trace(), b.trace());
  for (int i = 0; i < 4; ++i)
    if (d(i, i) < -tolerance) return false;
  return Eigen::SelfAdjointEigenSolver<Mat4>(d, Eigen::EigenvaluesOnly).eigenvalues()(0) >= -tolerance;
}

bool on_path(const std::vector<Label>& labels, int label, int node) {
  for (int l = label; l >= 0; l = labels[l].parent)
    if (labels[l].node == node) return true;
  return false;
}

PlanResult unwind(const std::vector<Label>& labels, int label) {
  PlanResult r;
  r.found = true;
  r.length_m = labels[label].length;
  r.goal_covariance = labels[label].sigma;
  for (int l = label; l >= 0; l = labels[l].parent) {
    r.nodes.push_back(labels[l].node);
    r.traces.push_back(labels[l].sigma.trace());
  }
  std::reverse(r.nodes.begin(), r.nodes.end());
  std::reverse(r.traces.begin(), r.traces.end());
  return r;
}

void check_nodes(const Roadmap& map, int start, int goal) {
  if (start < 0 || goal < 0 || start >= map.size() || goal >= map.size())
    throw std::invalid_argument("search: start or goal is not a node of the roadmap");
}

}  // namespace

PlanResult shortest_path(const Roadmap& map, int start, int goal) {
  check_nodes(map, start, goal);
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> dist(map.size(), inf);
  std::vector<int> parent(map.size(), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  dist[start] = 0.0;
  open.push({0.0, start});
  PlanResult r;
  while (!open.empty()) {
    const auto [d, n] = open.top();
    open.pop();
    if (d > dist[n]) continue;
    ++r.expansions;
    if (n == goal) break;
    for (const Edge& e : map.edges(n))
      if (d + e.length_m < dist[e.to]) {
        dist[e.to] = d + e.length_m;
        parent[e.to] = n;
        open.push({dist[e.to], e.to});
      }
  }
  if (dist[goal] == inf) return r;
  r.found = true;
  r.length_m = dist[goal];
  for (int n = goal; n >= 0; n = parent[n]) r.nodes.push_back(n);
  std::reverse(r.nodes.begin(), r.nodes.end());
  return r;
}

PlanResult belief_search(const Roadmap& map, int start, int goal, const BrmQuery& query) {
  check_nodes(map, start, goal);
  const bool shortest = query.objective == BrmObjective::kShortestBounded;
  const bool by_matrix = query.pruning == BrmPruning::kCovarianceDominance;
  std::vector<Label> labels{{start, -1, 0.0, query.start_covariance, query.start_covariance.trace(), false}};
  std::vector<std::vector<int>> front(map.size());  // labels alive at each node
  front[start].push_back(0);
  // `a` makes `b` redundant at their node: no longer (when length counts) and no worse
  // localised: by trace (Algorithm 1's rule) or in every direction (covariance dominance).
  // The slack widens only the rejection of a newcomer; a label already kept is superseded only
  // by exact dominance, so a dropped label is within (1 + slack) of one that survives, never
  // of a chain of them.
  const auto beats = [&](const Label& a, const Label& b, double slack) {
    if (shortest && a.length > b.length) return false;
    if (!by_matrix) return a.trace <= b.trace;
    const double scale = 1.0 + slack;
    return a.trace <= scale * b.trace && loewner_leq(a.sigma, scale * b.sigma);  // tr: cheap, necessary
  };
  // Best-first: by length for the bounded shortest path (the goal's first label is the answer),
  // by tr(Sigma) otherwise (Algorithm 1 is FIFO; this order re-expands far less). A label
  // superseded at its node before its turn is skipped.
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  open.push({shortest ? 0.0 : labels[0].trace, 0});
  long expansions = 0;
  while (!open.empty()) {
    const int l = open.top().second;
    open.pop();
    if (labels[l].superseded || (!shortest && labels[l].node == goal)) continue;
    ++expansions;
    if (labels[l].node == goal) {
      PlanResult r = unwind(labels, l);
      r.expansions = expansions;
      return r;
    }
    for (const Edge& e : map.edges(labels[l].node)) {
      if (on_path(labels, l, e.to)) continue;
      Label next{e.to, l, labels[l].length + e.length_m, e.transfer.apply(labels[l].sigma), 0.0, false};
      next.trace = next.sigma.trace();
      if (!(next.trace < query.max_trace)) continue;
      std::vector<int>& here = front[e.to];
      const auto kept_beats_next = [&](int k) { return beats(labels[k], next, query.dominance_slack); };
      if (std::any_of(here.begin(), here.end(), kept_beats_next)) continue;
      if (query.edge_peak_trace && !(query.edge_peak_trace(labels[l].node, e.to, labels[l].sigma) < query.max_trace))
        continue;
      for (int k : here) labels[k].superseded = beats(next, labels[k], 0.0);
      here.erase(std::remove_if(here.begin(), here.end(), [&](int k) { return labels[k].superseded; }), here.end());
      labels.push_back(std::move(next));
      const int id = static_cast<int>(labels.size()) - 1;
      here.push_back(id);
      open.push({shortest ? labels[id].length : labels[id].trace, id});
    }
  }
  PlanResult r;
  if (!shortest && !front[goal].empty())
    r = unwind(labels, *std::min_element(front[goal].begin(), front[goal].end(),
                                         [&](int a, int b) { return labels[a].trace < labels[b].trace; }));
  r.expansions = expansions;
  return r;
}

void predict_along(const Roadmap& map, const Mat4& start_covariance, PlanResult& path) {
  path.traces.clear();
  Mat4 sigma = start_covariance;
  if (path.nodes.empty()) return;
  path.traces.push_back(sigma.trace());
  for (size_t i = 1; i < path.nodes.size(); ++i) {
    const auto& edges = map.edges(path.nodes[i - 1]);
    const auto it = std::find_if(edges.begin(), edges.end(), [&](const Edge& e) { return e.to == path.nodes[i]; });
    if (it == edges.end()) throw std::invalid_argument("predict_along: consecutive nodes are not joined");
    sigma = it->transfer.apply(sigma);
    path.traces.push_back(sigma.trace());
  }
  path.goal_covariance = sigma;
}

}  // namespace kestrel::planner
