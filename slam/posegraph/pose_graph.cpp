#include "slam/posegraph/pose_graph.h"

#include <algorithm>
#include <deque>
#include <stdexcept>

namespace kestrel::slam {
namespace {

bool finite_pose(const Se2::Pose& p) { return p.allFinite(); }
bool finite_pose(const Se3::Pose& p) { return p.matrix().allFinite(); }

}  // namespace

template <class Space>
void check_graph(const PoseGraph<Space>& graph) {
  const int n = graph.num_vertices();
  if (graph.ids.size() != graph.poses.size() || graph.fixed.size() != graph.poses.size()) {
    throw std::invalid_argument("pose graph: ids, poses and fixed differ in length");
  }
  for (int v = 0; v < n; ++v) {
    if (!finite_pose(graph.poses[v])) {
      throw std::invalid_argument("pose graph: vertex " + std::to_string(graph.ids[v]) +
                                  " has a non-finite pose");
    }
  }
  for (const auto& e : graph.edges) {
    const std::string name = "pose graph: edge " + std::to_string(e.from) + " -> " +
                             std::to_string(e.to);
    if (e.from < 0 || e.from >= n || e.to < 0 || e.to >= n) {
      throw std::invalid_argument(name + " refers to a missing vertex");
    }
    if (e.from == e.to) throw std::invalid_argument(name + " joins a vertex to itself");
    if (!finite_pose(e.measurement) || !e.information.allFinite()) {
      throw std::invalid_argument(name + " has a non-finite value");
    }
    if (!e.information.isApprox(e.information.transpose(), 1e-9)) {
      throw std::invalid_argument(name + " has a non-symmetric information matrix");
    }
  }
}

template <class Space>
double edge_chi2(const PoseGraph<Space>& graph, const typename PoseGraph<Space>::Edge& edge) {
  const typename Space::Vector e = Space::error(
      graph.poses[edge.from], graph.poses[edge.to], Space::inverse(edge.measurement));
  return e.dot(edge.information * e);
}

template <class Space>
double chi2(const PoseGraph<Space>& graph) {
  double sum = 0.0;
  for (const auto& edge : graph.edges) sum += edge_chi2(graph, edge);
  return sum;
}

template <class Space>
std::vector<int> unknown_indices(const PoseGraph<Space>& graph, int* num_unknowns) {
  const int n = graph.num_vertices();
  const bool any_fixed = std::find(graph.fixed.begin(), graph.fixed.end(), 1) != graph.fixed.end();
  std::vector<int> index(n, -1);
  int next = 0;
  for (int v = 0; v < n; ++v) {
    const bool is_fixed = any_fixed ? graph.fixed[v] != 0 : v == 0;
    if (!is_fixed) index[v] = next++;
  }
  *num_unknowns = next;
  return index;
}

template <class Space>
std::vector<std::vector<int>> unanchored_components(const PoseGraph<Space>& graph) {
  const int n = graph.num_vertices();
  std::vector<std::vector<int>> neighbours(n);
  for (const auto& e : graph.edges) {
    neighbours[e.from].push_back(e.to);
    neighbours[e.to].push_back(e.from);
  }
  // Component label per vertex, -1 until reached; the anchored vertices' components first.
  std::vector<int> label(n, -1);
  const auto flood = [&](int start, int id, std::vector<int>* members) {
    std::vector<int> stack{start};
    label[start] = id;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      if (members != nullptr) members->push_back(v);
      for (const int w : neighbours[v]) {
        if (label[w] < 0) {
          label[w] = id;
          stack.push_back(w);
        }
      }
    }
  };
  const bool any_fixed = std::find(graph.fixed.begin(), graph.fixed.end(), 1) != graph.fixed.end();
  for (int v = 0; v < n; ++v) {
    if (label[v] < 0 && (any_fixed ? graph.fixed[v] != 0 : v == 0)) flood(v, 0, nullptr);
  }
  std::vector<std::vector<int>> unanchored;
  for (int v = 0; v < n; ++v) {
    if (label[v] >= 0) continue;
    unanchored.emplace_back();
    flood(v, static_cast<int>(unanchored.size()), &unanchored.back());
    std::sort(unanchored.back().begin(), unanchored.back().end());
  }
  return unanchored;
}

template <class Space>
void initialize_by_chaining(PoseGraph<Space>& graph) {
  const int n = graph.num_vertices();
  if (n == 0) return;
  // 0-1 breadth-first search: odometry edges cost nothing, others one, so a complete
  // odometry chain is followed in order and loop closures only bridge its gaps.
  std::vector<std::vector<int>> incident(n);
  for (int k = 0; k < graph.num_edges(); ++k) {
    incident[graph.edges[k].from].push_back(k);
    incident[graph.edges[k].to].push_back(k);
  }
  std::vector<int> cost(n, -1);
  std::deque<int> queue;
  bool any_fixed = false;
  for (int v = 0; v < n; ++v) {
    if (graph.fixed[v]) {
      cost[v] = 0;
      queue.push_back(v);
      any_fixed = true;
    }
  }
  if (!any_fixed) {
    cost[0] = 0;
    queue.push_back(0);
  }
  std::vector<char> done(n, 0);
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    if (done[v]) continue;
    done[v] = 1;
    for (const int k : incident[v]) {
      const auto& e = graph.edges[k];
      const int w = e.from == v ? e.to : e.from;
      if (done[w]) continue;
      const int step = e.kind == EdgeKind::kOdometry ? 0 : 1;
      if (cost[w] >= 0 && cost[w] <= cost[v] + step) continue;
      cost[w] = cost[v] + step;
      graph.poses[w] = e.from == v ? Space::compose(graph.poses[v], e.measurement)
                                   : Space::compose(graph.poses[v], Space::inverse(e.measurement));
      if (step == 0) {
        queue.push_front(w);
      } else {
        queue.push_back(w);
      }
    }
  }
  for (int v = 0; v < n; ++v) {
    if (!done[v]) {
      throw std::invalid_argument("pose graph: vertex " + std::to_string(graph.ids[v]) +
                                  " is not connected to an anchored vertex");
    }
  }
}

template void check_graph(const PoseGraph<Se2>&);
template void check_graph(const PoseGraph<Se3>&);
template double chi2(const PoseGraph<Se2>&);
template double chi2(const PoseGraph<Se3>&);
template double edge_chi2(const PoseGraph<Se2>&, const PoseGraph<Se2>::Edge&);
template double edge_chi2(const PoseGraph<Se3>&, const PoseGraph<Se3>::Edge&);
template std::vector<int> unknown_indices(const PoseGraph<Se2>&, int*);
template std::vector<int> unknown_indices(const PoseGraph<Se3>&, int*);
template std::vector<std::vector<int>> unanchored_components(const PoseGraph<Se2>&);
template std::vector<std::vector<int>> unanchored_components(const PoseGraph<Se3>&);
template void initialize_by_chaining(PoseGraph<Se2>&);
template void initialize_by_chaining(PoseGraph<Se3>&);

}  // namespace kestrel::slam
