#include "slam/posegraph/chordal_init.h"

#include "common/geometry/so3.h"
#include "slam/posegraph/block_system.h"

namespace kestrel::slam {
namespace {

// One residual A_i x_i + A_j x_j + c of a linear least-squares problem in blocks of D x R
// (R right-hand sides solved together), weighted by W. A fixed end has index -1 and its
// contribution is folded into c.
template <int D, int R>
struct Term {
  int i = -1, j = -1;
  int pair = -1;  // index of the (i, j) block pair when both ends are unknown
  Eigen::Matrix<double, D, D> Ai, Aj, W;
  Eigen::Matrix<double, D, R> c;
};

template <int D, int R>
bool solve_terms(BlockSystem<D>& system, const std::vector<Term<D, R>>& terms,
                 Eigen::MatrixXd& x) {
  system.set_zero();
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(system.num_blocks()) * D, R);
  for (const auto& t : terms) {
    if (t.i >= 0) {
      system.diagonal(t.i) += t.Ai.transpose() * t.W * t.Ai;
      b.template middleRows<D>(t.i * D) -= t.Ai.transpose() * t.W * t.c;
    }
    if (t.j >= 0) {
      system.diagonal(t.j) += t.Aj.transpose() * t.W * t.Aj;
      b.template middleRows<D>(t.j * D) -= t.Aj.transpose() * t.W * t.c;
    }
    if (t.pair >= 0) {
      system.offdiagonal(t.pair) +=
          t.i < t.j ? Eigen::Matrix<double, D, D>(t.Ai.transpose() * t.W * t.Aj)
                    : Eigen::Matrix<double, D, D>(t.Aj.transpose() * t.W * t.Ai);
    }
  }
  if (!system.factorize()) return false;
  x = system.solve_factored(b);
  return x.allFinite();
}

// The unknowns (free vertices), the pairs of unknowns joined by an edge, and their order.
struct Topology {
  std::vector<int> index;  // per vertex: unknown index or -1
  int num_unknowns = 0;
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> pair_of_edge;  // per edge: index into pairs or -1
  std::vector<int> order;         // fill-reducing order of the unknowns
};

template <class Space>
Topology topology(const PoseGraph<Space>& graph, const std::vector<int>& vertex_order) {
  Topology t;
  t.index = unknown_indices(graph, &t.num_unknowns);
  t.pair_of_edge.assign(graph.edges.size(), -1);
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const int i = t.index[graph.edges[k].from], j = t.index[graph.edges[k].to];
    if (i >= 0 && j >= 0) {
      t.pair_of_edge[k] = static_cast<int>(t.pairs.size());
      t.pairs.emplace_back(i, j);
    }
  }
  if (vertex_order.size() == graph.poses.size()) {
    // Leaving the fixed vertices out of a good order of all vertices keeps it good.
    for (const int v : vertex_order) {
      if (t.index[v] >= 0) t.order.push_back(t.index[v]);
    }
  } else {
    t.order = order_blocks(t.num_unknowns, t.pairs);
  }
  return t;
}

// Fills the unknown ends of a term, folding a fixed end's value into c.
template <int D, int R>
void set_ends(Term<D, R>& term, const Topology& topo, int from, int to, int k,
              const Eigen::Matrix<double, D, R>& x_from, const Eigen::Matrix<double, D, R>& x_to) {
  term.i = topo.index[from];
  term.j = topo.index[to];
  term.pair = topo.pair_of_edge[k];
  if (term.i < 0) term.c += term.Ai * x_from;
  if (term.j < 0) term.c += term.Aj * x_to;
}

// Positions given the rotations: w |t_j - t_i - R_i t_ij|^2 with the graph Laplacian, one
// right-hand side per coordinate. `rotate(v, t)` gives R_v t; `position(v)` the current value.
template <int N, class Graph, class Rotate, class Position>
bool solve_positions(const Graph& graph, const Topology& topo, Rotate rotate, Position position,
                     Eigen::MatrixXd& x) {
  using Row = Eigen::Matrix<double, 1, N>;
  std::vector<Term<1, N>> terms;
  terms.reserve(graph.edges.size());
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& e = graph.edges[k];
    const double w = e.information.template topLeftCorner<N, N>().trace() / N;
    if (!(w > 0.0)) continue;
    Term<1, N> t;
    t.Ai(0, 0) = -1.0;
    t.Aj(0, 0) = 1.0;
    t.W(0, 0) = w;
    const Eigen::Matrix<double, N, 1> m = rotate(e.from, e.measurement);
    t.c = -m.transpose();
    set_ends<1, N>(t, topo, e.from, e.to, static_cast<int>(k), Row(position(e.from).transpose()),
                   Row(position(e.to).transpose()));
    terms.push_back(t);
  }
  BlockSystem<1> system(topo.num_unknowns, topo.pairs, topo.order);
  return solve_terms(system, terms, x);
}

}  // namespace

bool chordal_initialize(PoseGraph3d& graph, const std::vector<int>& vertex_order) {
  const Topology topo = topology(graph, vertex_order);
  if (topo.num_unknowns == 0) return true;
  const int m = graph.num_edges();

  // Rotations: x_v = R_v^T, so that R_j = R_i R_ij reads x_j - R_ij^T x_i = 0.
  std::vector<Term<3, 3>> rot;
  rot.reserve(m);
  for (int k = 0; k < m; ++k) {
    const auto& e = graph.edges[k];
    const double kappa = e.information.template bottomRightCorner<3, 3>().trace() / 3.0;
    if (!(kappa > 0.0)) continue;
    Term<3, 3> t;
    t.Ai = -e.measurement.linear().transpose();
    t.Aj.setIdentity();
    t.W = kappa * Eigen::Matrix3d::Identity();
    t.c.setZero();
    set_ends<3, 3>(t, topo, e.from, e.to, k, graph.poses[e.from].linear().transpose(),
                   graph.poses[e.to].linear().transpose());
    rot.push_back(t);
  }
  Eigen::MatrixXd x;
  {
    BlockSystem<3> system(topo.num_unknowns, topo.pairs, topo.order);
    if (!solve_terms(system, rot, x)) return false;
  }
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> R(graph.num_vertices());
  for (int v = 0; v < graph.num_vertices(); ++v) {
    const int u = topo.index[v];
    R[v] = u < 0 ? Eigen::Matrix3d(graph.poses[v].linear())
                 : so3::orthonormalize(x.middleRows<3>(3 * u).transpose());
  }

  Eigen::MatrixXd t;
  const bool ok = solve_positions<3>(
      graph, topo,
      [&](int v, const Se3::Pose& Z) { return Eigen::Vector3d(R[v] * Z.translation()); },
      [&](int v) { return Eigen::Vector3d(graph.poses[v].translation()); }, t);
  if (!ok) return false;
  for (int v = 0; v < graph.num_vertices(); ++v) {
    const int u = topo.index[v];
    if (u < 0) continue;
    graph.poses[v].linear() = R[v];
    graph.poses[v].translation() = t.row(u).transpose();
  }
  return true;
}

bool chordal_initialize(PoseGraph2d& graph, const std::vector<int>& vertex_order) {
  const Topology topo = topology(graph, vertex_order);
  if (topo.num_unknowns == 0) return true;
  const int m = graph.num_edges();

  // Rotations as unit complex numbers x_v = (cos, sin): x_j - R(theta_ij) x_i = 0.
  std::vector<Term<2, 1>> rot;
  rot.reserve(m);
  auto unit = [](double theta) { return Eigen::Vector2d(std::cos(theta), std::sin(theta)); };
  for (int k = 0; k < m; ++k) {
    const auto& e = graph.edges[k];
    const double kappa = e.information(2, 2);
    if (!(kappa > 0.0)) continue;
    Term<2, 1> t;
    t.Ai = -Se2::rotation(e.measurement.z());
    t.Aj.setIdentity();
    t.W = kappa * Eigen::Matrix2d::Identity();
    t.c.setZero();
    set_ends<2, 1>(t, topo, e.from, e.to, k, unit(graph.poses[e.from].z()),
                   unit(graph.poses[e.to].z()));
    rot.push_back(t);
  }
  Eigen::MatrixXd x;
  {
    BlockSystem<2> system(topo.num_unknowns, topo.pairs, topo.order);
    if (!solve_terms(system, rot, x)) return false;
  }
  std::vector<double> theta(graph.num_vertices());
  for (int v = 0; v < graph.num_vertices(); ++v) {
    const int u = topo.index[v];
    theta[v] = u < 0 ? graph.poses[v].z() : std::atan2(x(2 * u + 1, 0), x(2 * u, 0));
  }

  Eigen::MatrixXd t;
  const bool ok = solve_positions<2>(
      graph, topo,
      [&](int v, const Se2::Pose& Z) { return Eigen::Vector2d(Se2::rotation(theta[v]) * Z.head<2>()); },
      [&](int v) { return Eigen::Vector2d(graph.poses[v].head<2>()); }, t);
  if (!ok) return false;
  for (int v = 0; v < graph.num_vertices(); ++v) {
    const int u = topo.index[v];
    if (u < 0) continue;
    graph.poses[v] = Se2::Pose(t(u, 0), t(u, 1), theta[v]);
  }
  return true;
}

}  // namespace kestrel::slam
