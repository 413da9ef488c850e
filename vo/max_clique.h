#pragma once
// Inlier detection without sampling (Howard 2008, fovis): matches are the vertices of a graph
// with an edge wherever a rigid motion could explain both, i.e. the distance between the two
// points is preserved between the frames; the inliers are a large clique, found greedily.
//
// Invariants: the graph is symmetric without self-loops; greedy_max_clique() returns a clique
// (pairwise adjacent vertices) that is maximal (no vertex can be added), in increasing order.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace kestrel::vo {

/// An undirected graph as bit rows: adjacent(a, b) is bit b of row a.
class BitGraph {
 public:
  void reset(int vertices);
  void connect(int a, int b);
  bool adjacent(int a, int b) const {
    return (row(a)[static_cast<size_t>(b) >> 6] >> (b & 63)) & 1u;
  }
  int size() const { return n_; }
  int words() const { return words_; }
  const uint64_t* row(int a) const { return bits_.data() + static_cast<size_t>(a) * static_cast<size_t>(words_); }
  uint64_t* row(int a) { return bits_.data() + static_cast<size_t>(a) * static_cast<size_t>(words_); }
  int degree(int a) const;

 private:
  int n_ = 0, words_ = 0;
  std::vector<uint64_t> bits_;
};

/// The greedy clique: start from the vertex of highest degree, then keep adding the vertex of
/// highest degree adjacent to every vertex taken so far (ties: lower index first).
std::vector<int> greedy_max_clique(const BitGraph& graph);

/// Builds the consistency graph of matches (ref_points[i] <-> cur_points[i], metres): an edge
/// when | |P_a - P_b| - |Q_a - Q_b| | < max(min_tolerance, sigmas * sqrt(var[a] + var[b])),
/// where var[i] is the variance (m^2) of point i's position error in both frames together.
void build_consistency_graph(const std::vector<Eigen::Vector3f>& ref_points,
                             const std::vector<Eigen::Vector3f>& cur_points,
                             const std::vector<float>& variances, float min_tolerance,
                             float sigmas, BitGraph& graph);

}  // namespace kestrel::vo
