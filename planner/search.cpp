// PRM Dijkstra and the BRM label search.
#include "planner/search.h"

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
};

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
  std::vector<Label> labels{{start, -1, 0.0, query.start_covariance}};
  long expansions = 0;
  if (query.objective == BrmObjective::kMinGoalUncertainty) {
    std::vector<double> best(map.size(), std::numeric_limits<double>::infinity());
    std::vector<int> best_label(map.size(), -1);
    best[start] = query.start_covariance.trace();
    best_label[start] = 0;
    // Algorithm 1's acceptance rule, expanded best-first by tr(Sigma) rather than in FIFO order,
    // and skipping labels superseded at their node before their turn: far fewer re-expansions.
    // Like the FIFO original this is a heuristic (pruning by tr at a node can drop a label that
    // would do better later), so the two may return different, equally plausible paths.
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    open.push({best[start], 0});
    while (!open.empty()) {
      const auto [tr_l, l] = open.top();
      open.pop();
      if (tr_l > best[labels[l].node]) continue;  // a better label reached this node since
      ++expansions;
      for (const Edge& e : map.edges(labels[l].node)) {
        if (on_path(labels, l, e.to)) continue;
        const Mat4 sigma = e.transfer.apply(labels[l].sigma);
        const double tr = sigma.trace();
        if (!(tr < best[e.to]) || !(tr < query.max_trace)) continue;
        if (query.edge_peak_trace && !(query.edge_peak_trace(labels[l].node, e.to, labels[l].sigma) < query.max_trace))
          continue;
        best[e.to] = tr;
        labels.push_back({e.to, l, labels[l].length + e.length_m, sigma});
        best_label[e.to] = static_cast<int>(labels.size()) - 1;
        if (e.to != goal) open.push({tr, best_label[e.to]});
      }
    }
    PlanResult r = best_label[goal] >= 0 ? unwind(labels, best_label[goal]) : PlanResult{};
    r.expansions = expansions;
    return r;
  }
  // Shortest with a bound: best-first on length over Pareto-optimal (length, trace) labels.
  std::vector<std::vector<std::pair<double, double>>> front(map.size());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  open.push({0.0, 0});
  while (!open.empty()) {
    const int l = open.top().second;
    open.pop();
    ++expansions;
    if (labels[l].node == goal) {
      PlanResult r = unwind(labels, l);
      r.expansions = expansions;
      return r;
    }
    for (const Edge& e : map.edges(labels[l].node)) {
      if (on_path(labels, l, e.to)) continue;
      const Mat4 sigma = e.transfer.apply(labels[l].sigma);
      const double tr = sigma.trace(), len = labels[l].length + e.length_m;
      if (!(tr < query.max_trace)) continue;
      auto& f = front[e.to];
      if (std::any_of(f.begin(), f.end(), [&](const auto& p) { return p.first <= len && p.second <= tr; }))
        continue;
      if (query.edge_peak_trace && !(query.edge_peak_trace(labels[l].node, e.to, labels[l].sigma) < query.max_trace))
        continue;
      f.erase(std::remove_if(f.begin(), f.end(), [&](const auto& p) { return p.first >= len && p.second >= tr; }),
              f.end());
      f.push_back({len, tr});
      labels.push_back({e.to, l, len, sigma});
      open.push({len, static_cast<int>(labels.size()) - 1});
    }
  }
  PlanResult r;
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
