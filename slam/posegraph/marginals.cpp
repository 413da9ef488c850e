#include "slam/posegraph/marginals.h"

#include <stdexcept>

#include "slam/posegraph/normal_equations.h"

namespace kestrel::slam {

template <class Space>
std::optional<typename Space::Matrix> marginal_covariance(const PoseGraph<Space>& graph, int vertex,
                                                          const RobustKernel& kernel) {
  using Matrix = typename Space::Matrix;
  constexpr int D = Space::kDim;
  check_graph(graph);
  if (vertex < 0 || vertex >= graph.num_vertices()) {
    throw std::invalid_argument("marginal_covariance: no vertex " + std::to_string(vertex));
  }
  // The gauge stays fixed here: the optimiser's free gauge would add the (huge, arbitrary)
  // uncertainty of the whole graph's placement to every pose.
  NormalEquations<Space> equations(graph, kernel, {}, false);
  const int u = equations.num_unknowns() > 0 ? equations.unknown_of(vertex) : -1;
  if (u < 0) return Matrix::Zero();
  equations.linearize(graph.poses);
  auto& system = equations.system();
  if (!system.factorize(0.0, 0.0)) return std::nullopt;
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(equations.num_unknowns()) * D, D);
  unit.block<D, D>(static_cast<Eigen::Index>(u) * D, 0).setIdentity();
  const Eigen::MatrixXd columns = system.solve_factored(unit);
  Matrix covariance = columns.block<D, D>(static_cast<Eigen::Index>(u) * D, 0);
  covariance = 0.5 * (covariance + covariance.transpose()).eval();
  if (!covariance.allFinite()) return std::nullopt;
  return covariance;
}

template std::optional<Se2::Matrix> marginal_covariance(const PoseGraph<Se2>&, int, const RobustKernel&);
template std::optional<Se3::Matrix> marginal_covariance(const PoseGraph<Se3>&, int, const RobustKernel&);

}  // namespace kestrel::slam
