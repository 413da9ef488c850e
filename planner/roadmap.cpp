// Roadmap construction and the holonomic belief model of its edges.
#include "planner/roadmap.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "common/gaussian/information.h"
#include "common/numbers.h"

namespace kestrel::planner {

std::vector<BeliefStep> BeliefModel::steps(const Config& a, const Config& b) const {
  std::vector<BeliefStep> out;
  const Eigen::Vector3d d = position(b) - position(a);
  const double len = d.norm();
  if (!(len > 0.0)) return out;
  const double turn = wrap_angle(b[3] - a[3]);
  const int n = std::max({1, static_cast<int>(std::ceil(len / motion_.step_m)),
                          static_cast<int>(std::ceil(std::abs(turn) / motion_.step_rad))});
  const Eigen::Vector4d variances = motion_.variance_per_m * (len / n);
  out.reserve(n);
  for (int k = 1; k <= n; ++k) {
    const double f = static_cast<double>(k) / n;
    Config q;
    q << position(a) + d * f, wrap_angle(a[3] + f * turn);
    BeliefStep s;
    s.G = Mat4::Identity();
    s.R = gaussian::process_noise_diagonal(Mat4::Identity(), variances);
    s.M = information_(q);
    out.push_back(s);
  }
  return out;
}

double peak_trace_along(const BeliefModel& model, const Config& a, const Config& b, const Mat4& sigma) {
  Mat4 S = sigma;
  const std::vector<BeliefStep> steps = model.steps(a, b);
  if (steps.empty()) return S.trace();
  double peak = 0.0;
  for (const BeliefStep& s : steps) {
    S = propagate_ekf(S, {s});
    peak = std::max(peak, S.trace());
  }
  return peak;
}

int Roadmap::add_node(const Config& q) {
  nodes_.push_back(q);
  adjacency_.emplace_back();
  return size() - 1;
}

void Roadmap::add_edge(int from, int to, double length_m, const ScatteringTransfer& transfer) {
  adjacency_.at(from).push_back(Edge{to, length_m, transfer});
  (void)adjacency_.at(to);
}

void Roadmap::connect(int a, int b, const BeliefModel* model) {
  const double len = ConfigurationSpace::distance(nodes_[a], nodes_[b]);
  ScatteringTransfer ab, ba;
  if (model) {
    ab = ScatteringTransfer::from_steps(model->steps(nodes_[a], nodes_[b]));
    ba = ScatteringTransfer::from_steps(model->steps(nodes_[b], nodes_[a]));
  }
  add_edge(a, b, len, ab);
  add_edge(b, a, len, ba);
}

int Roadmap::edge_count() const {
  int n = 0;
  for (const auto& e : adjacency_) n += static_cast<int>(e.size());
  return n;
}

namespace {

// Each node's nearest max_neighbours within the radius; each pair once, as (lower, higher).
std::vector<std::pair<int, int>> candidate_pairs(const std::vector<Config>& nodes, const RoadmapOptions& options) {
  std::vector<std::pair<int, int>> pairs;
  const int n = static_cast<int>(nodes.size());
  std::vector<std::pair<double, int>> near;
  for (int a = 0; a < n; ++a) {
    near.clear();
    for (int b = 0; b < n; ++b) {
      const double d = ConfigurationSpace::distance(nodes[a], nodes[b]);
      if (b != a && d <= options.connect_radius_m) near.push_back({d, b});
    }
    std::sort(near.begin(), near.end());
    if (options.max_neighbours > 0 && static_cast<int>(near.size()) > options.max_neighbours)
      near.resize(options.max_neighbours);
    for (const auto& [d, b] : near) pairs.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

bool connected(int n, const std::vector<std::pair<int, int>>& edges, int from, int to) {
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& [a, b] : edges) parent[root(a)] = root(b);
  return root(from) == root(to);
}

}  // namespace

Roadmap build_roadmap(const ConfigurationSpace& space, Sampler& sampler, const Config& start,
                      const Config& goal, const RoadmapOptions& options, const BeliefModel* model, Rng& rng) {
  std::vector<Config> nodes{start, goal};
  bool exhausted = false;
  const auto draw = [&](int count) {
    for (int i = 0; i < count && !exhausted; ++i) {
      const std::optional<Config> q = sampler.sample(rng);
      if (q) nodes.push_back(*q);
      else exhausted = true;  // the sampler cannot find more: plan on what there is
    }
  };
  // Collision checks are the cost of a connection attempt: each pair is checked once however
  // often the roadmap grows.
  std::map<std::pair<int, int>, bool> valid;
  std::vector<std::pair<int, int>> edges;
  const auto connect_all = [&] {
    edges.clear();
    for (const auto& ab : candidate_pairs(nodes, options)) {
      auto [it, inserted] = valid.try_emplace(ab, false);
      if (inserted) it->second = space.motion_valid(nodes[ab.first], nodes[ab.second]);
      if (it->second) edges.push_back(ab);
    }
  };
  draw(options.samples);
  connect_all();
  const int budget = std::max(options.samples, options.max_samples);
  while (!exhausted && static_cast<int>(nodes.size()) - 2 < budget &&
         !connected(static_cast<int>(nodes.size()), edges, 0, 1)) {
    draw(std::min(std::max(options.samples, 1), budget - (static_cast<int>(nodes.size()) - 2)));
    connect_all();
  }
  Roadmap map;
  for (const Config& q : nodes) map.add_node(q);
  for (const auto& [a, b] : edges) map.connect(a, b, model);
  return map;
}

}  // namespace kestrel::planner
