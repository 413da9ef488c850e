#pragma once
// A pose graph: poses (vertices) joined by measured relative poses (edges), each with its
// information matrix, in SE(2) or SE(3) (slam/posegraph/spaces.h gives the error convention).
//
// Invariants (check_graph() enforces them): edges refer to vertices by index; no edge joins a
// vertex to itself; information matrices are symmetric with finite entries; poses are finite.
// At least one vertex is fixed (the gauge); when none is marked, the optimiser fixes vertex 0,
// and it holds each component that reaches no fixed vertex at its first vertex (optimizer.h).

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "slam/posegraph/spaces.h"

namespace kestrel::slam {

/// Odometry edges join consecutive poses; loop closures the rest. The robust kernel of the
/// optimiser applies to loop closures only, whose outliers are the ones to fear.
enum class EdgeKind : int8_t { kOdometry = 0, kLoopClosure = 1 };

template <class Space>
struct PoseGraph {
  using Pose = typename Space::Pose;
  using Information = typename Space::Matrix;

  struct Edge {
    int from = 0;  ///< index into poses
    int to = 0;
    Pose measurement = Space::identity();  ///< Z = X_from^-1 * X_to when all agree
    Information information = Information::Identity();
    EdgeKind kind = EdgeKind::kOdometry;
  };

  std::vector<int64_t> ids;   ///< external vertex ids (g2o ids, keyframe ids), one per pose
  std::vector<Pose> poses;    ///< current estimates
  std::vector<char> fixed;    ///< 1 = held constant by the optimiser
  std::vector<Edge> edges;

  int num_vertices() const { return static_cast<int>(poses.size()); }
  int num_edges() const { return static_cast<int>(edges.size()); }

  /// Appends a vertex; returns its index.
  int add_vertex(int64_t id, const Pose& pose, bool is_fixed = false) {
    ids.push_back(id);
    poses.push_back(pose);
    fixed.push_back(is_fixed ? 1 : 0);
    return num_vertices() - 1;
  }
  void add_edge(int from, int to, const Pose& measurement, const Information& information,
                EdgeKind kind) {
    edges.push_back(Edge{from, to, measurement, information, kind});
  }
};

using PoseGraph2d = PoseGraph<Se2>;
using PoseGraph3d = PoseGraph<Se3>;

/// Throws std::invalid_argument naming the first broken invariant (the readers report bad
/// files themselves, with their line; this guards graphs built in code).
template <class Space>
void check_graph(const PoseGraph<Space>& graph);

/// Sum over edges of e^T Omega e (no robust kernel).
template <class Space>
double chi2(const PoseGraph<Space>& graph);

/// e^T Omega e of one edge.
template <class Space>
double edge_chi2(const PoseGraph<Space>& graph, const typename PoseGraph<Space>::Edge& edge);

/// For each vertex, its index among the unknowns, or -1 when it is held fixed (vertex 0 when
/// no vertex is marked fixed).
template <class Space>
std::vector<int> unknown_indices(const PoseGraph<Space>& graph, int* num_unknowns);

/// The connected components (vertices joined by edges) that hold no anchor: no fixed vertex
/// or, when none is marked, not vertex 0. Each is its vertex indices in increasing order; an
/// isolated vertex is a component of one. Empty when every vertex reaches an anchor. Such a
/// component is free to move rigidly, which no edge resists: its normal equations are singular.
template <class Space>
std::vector<std::vector<int>> unanchored_components(const PoseGraph<Space>& graph);

/// Sets every pose not reachable yet by chaining edge measurements outward from the fixed
/// vertices (vertex 0 when none is fixed): odometry edges (to = from + 1) first, in order,
/// then any other edge. Poses already reached keep their value. Throws std::invalid_argument
/// if some vertex is not connected to an anchored one.
template <class Space>
void initialize_by_chaining(PoseGraph<Space>& graph);

}  // namespace kestrel::slam
