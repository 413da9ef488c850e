// Roadmap construction and the holonomic belief model of its edges.
#include "planner/roadmap.h"

#include <algorithm>
#include <cmath>

#include "estimator/information.h"

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
    s.R = estimator::process_noise_diagonal(Mat4::Identity(), variances);
    s.M = information_(q);
    out.push_back(s);
  }
  return out;
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

Roadmap build_roadmap(const ConfigurationSpace& space, Sampler& sampler, const Config& start,
                      const Config& goal, const RoadmapOptions& options, const BeliefModel* model, Rng& rng) {
  Roadmap map;
  map.add_node(start);
  map.add_node(goal);
  for (int i = 0; i < options.samples; ++i) {
    const std::optional<Config> q = sampler.sample(rng);
    if (!q) break;  // the sampler cannot find more: plan on what there is
    map.add_node(*q);
  }
  // Candidate pairs: each node's nearest neighbours within the radius; a pair is tried once.
  std::vector<std::pair<int, int>> pairs;
  for (int a = 0; a < map.size(); ++a) {
    std::vector<std::pair<double, int>> near;
    for (int b = 0; b < map.size(); ++b) {
      const double d = ConfigurationSpace::distance(map.node(a), map.node(b));
      if (b != a && d <= options.connect_radius_m) near.push_back({d, b});
    }
    std::sort(near.begin(), near.end());
    if (options.max_neighbours > 0 && static_cast<int>(near.size()) > options.max_neighbours)
      near.resize(options.max_neighbours);
    for (const auto& [d, b] : near) pairs.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  for (const auto& [a, b] : pairs)
    if (space.motion_valid(map.node(a), map.node(b))) map.connect(a, b, model);
  return map;
}

}  // namespace kestrel::planner
