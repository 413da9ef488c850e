#include "slam/posegraph/normal_equations.h"

#include <Eigen/Cholesky>
#include <algorithm>

#include "common/geometry/se3.h"

namespace kestrel::slam {
namespace {

// The prior that holds the gauge vertex, relative to the mean diagonal of its block.
constexpr double kGaugePrior = 1e-6;

// The local coordinates (spaces.h retractions) of an infinitesimal rigid motion xi of the
// whole graph applied on the left: d = A xi.
Se2::Matrix rigid_motion_in_local(const Se2::Pose& X) {
  Se2::Matrix A = Se2::Matrix::Identity();  // SE(2) retracts in world coordinates
  A(0, 2) = -X.y();
  A(1, 2) = X.x();
  return A;
}
Se3::Matrix rigid_motion_in_local(const Se3::Pose& X) { return se3::adjoint(X.inverse()); }

}  // namespace

template <class Space>
NormalEquations<Space>::NormalEquations(const PoseGraph<Space>& graph, const RobustKernel& kernel,
                                        const std::vector<int>& vertex_order, bool free_gauge)
    : graph_(graph), kernel_(kernel) {
  index_ = unknown_indices(graph, &num_unknowns_);
  if (free_gauge && num_unknowns_ == graph.num_vertices() - 1) {
    // One fixed vertex: make it an unknown too (see the header).
    gauge_vertex_ = static_cast<int>(std::find(index_.begin(), index_.end(), -1) - index_.begin());
    num_unknowns_ = 0;
    for (auto& u : index_) u = num_unknowns_++;
  }
  pair_of_edge_.assign(graph.edges.size(), -1);
  std::vector<std::pair<int, int>> pairs;
  z_inv_.reserve(graph.edges.size());
  for (size_t k = 0; k < graph.edges.size(); ++k) {
    const auto& e = graph.edges[k];
    z_inv_.push_back(Space::inverse(e.measurement));
    const int i = index_[e.from], j = index_[e.to];
    if (i >= 0 && j >= 0) {
      pair_of_edge_[k] = static_cast<int>(pairs.size());
      pairs.emplace_back(i, j);
    }
  }
  if (num_unknowns_ == 0) return;
  std::vector<int> order;
  if (vertex_order.size() == graph.poses.size()) {
    for (const int v : vertex_order) {
      if (index_[v] >= 0) order.push_back(index_[v]);
    }
  } else {
    order = order_blocks(num_unknowns_, pairs);
  }
  system_ = std::make_unique<BlockSystem<D>>(num_unknowns_, pairs, order);
}

template <class Space>
double NormalEquations<Space>::kernel_weight(size_t k, double s) const {
  return graph_.edges[k].kind == EdgeKind::kLoopClosure ? kernel_.weight(s) : 1.0;
}

template <class Space>
double NormalEquations<Space>::kernel_cost(size_t k, double s) const {
  return graph_.edges[k].kind == EdgeKind::kLoopClosure ? kernel_.cost(s) : s;
}

template <class Space>
double NormalEquations<Space>::cost(const Poses& poses, bool robust) const {
  double sum = 0.0;
  for (size_t k = 0; k < graph_.edges.size(); ++k) {
    const auto& edge = graph_.edges[k];
    const typename Space::Vector e = Space::error(poses[edge.from], poses[edge.to], z_inv_[k]);
    const double s = e.dot(edge.information * e);
    sum += robust ? kernel_cost(k, s) : s;
  }
  return sum;
}

template <class Space>
double NormalEquations<Space>::linearize(const Poses& poses) {
  using Vec = typename Space::Vector;
  using Mat = typename Space::Matrix;
  BlockSystem<D>& sys = *system_;
  sys.set_zero();
  Eigen::VectorXd& b = sys.rhs();
  double sum = 0.0;
  Mat Ji, Jj;
  for (size_t k = 0; k < graph_.edges.size(); ++k) {
    const auto& edge = graph_.edges[k];
    const Vec e = Space::linearize(poses[edge.from], poses[edge.to], z_inv_[k], Ji, Jj);
    const Vec We = edge.information * e;
    const double s = e.dot(We);
    sum += kernel_cost(k, s);
    const double w = kernel_weight(k, s);
    const int i = index_[edge.from], j = index_[edge.to];
    const Mat JiW = w * (Ji.transpose() * edge.information);
    const Mat JjW = w * (Jj.transpose() * edge.information);
    if (i >= 0) {
      sys.diagonal(i).noalias() += JiW * Ji;
      b.template segment<D>(i * D).noalias() -= JiW * e;
    }
    if (j >= 0) {
      sys.diagonal(j).noalias() += JjW * Jj;
      b.template segment<D>(j * D).noalias() -= JjW * e;
    }
    if (pair_of_edge_[k] >= 0) {
      if (i < j) {
        sys.offdiagonal(pair_of_edge_[k]).noalias() += JiW * Jj;
      } else {
        sys.offdiagonal(pair_of_edge_[k]).noalias() += JjW * Ji;
      }
    }
  }
  if (gauge_vertex_ >= 0) {
    auto& H = sys.diagonal(index_[gauge_vertex_]);
    H.diagonal().array() += kGaugePrior * std::max(H.diagonal().mean(), 1e-12);
  }
  return sum;
}

template <class Space>
void NormalEquations<Space>::retract(const Poses& poses, const Eigen::VectorXd& dx,
                                     Poses& out) const {
  out = poses;
  for (size_t v = 0; v < poses.size(); ++v) {
    const int u = index_[v];
    if (u >= 0) out[v] = Space::retract(poses[v], dx.template segment<D>(u * D));
  }
}

template <class Space>
Eigen::VectorXd NormalEquations<Space>::acceleration_rhs(const Poses& poses,
                                                         const Eigen::VectorXd& dx,
                                                         double h) const {
  using Vec = typename Space::Vector;
  using Mat = typename Space::Matrix;
  Poses moved;
  retract(poses, h * dx, moved);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(dx.size());
  Mat Ji, Jj;
  for (size_t k = 0; k < graph_.edges.size(); ++k) {
    const auto& edge = graph_.edges[k];
    const Vec e0 = Space::linearize(poses[edge.from], poses[edge.to], z_inv_[k], Ji, Jj);
    const Vec eh = Space::error(moved[edge.from], moved[edge.to], z_inv_[k]);
    const int i = index_[edge.from], j = index_[edge.to];
    Vec Jdx = Vec::Zero();
    if (i >= 0) Jdx.noalias() += Ji * dx.template segment<D>(i * D);
    if (j >= 0) Jdx.noalias() += Jj * dx.template segment<D>(j * D);
    const Vec r_vv = (2.0 / h) * ((eh - e0) / h - Jdx);
    const double w = kernel_weight(k, e0.dot(edge.information * e0));
    const Vec Wr = w * (edge.information * r_vv);
    if (i >= 0) b.template segment<D>(i * D).noalias() -= Ji.transpose() * Wr;
    if (j >= 0) b.template segment<D>(j * D).noalias() -= Jj.transpose() * Wr;
  }
  return b;
}

template <class Space>
void NormalEquations<Space>::remove_rigid_motion(const Poses& poses, Eigen::VectorXd& dx) const {
  using Mat = typename Space::Matrix;
  using Vec = typename Space::Vector;
  if (gauge_vertex_ < 0) return;
  Mat N = Mat::Zero();
  Vec r = Vec::Zero();
  for (size_t v = 0; v < poses.size(); ++v) {
    const int u = index_[v];
    if (u < 0) continue;
    const Mat A = rigid_motion_in_local(poses[v]);
    N.noalias() += A.transpose() * A;
    r.noalias() += A.transpose() * dx.template segment<D>(u * D);
  }
  const Vec xi = N.ldlt().solve(r);
  if (!xi.allFinite()) return;
  for (size_t v = 0; v < poses.size(); ++v) {
    const int u = index_[v];
    if (u >= 0) dx.template segment<D>(u * D).noalias() -= rigid_motion_in_local(poses[v]) * xi;
  }
}

template <class Space>
Eigen::MatrixXd NormalEquations<Space>::rigid_motions(const Poses& poses) const {
  if (gauge_vertex_ < 0) return Eigen::MatrixXd(num_unknowns_ * D, 0);
  Eigen::MatrixXd W(num_unknowns_ * D, D);
  for (size_t v = 0; v < poses.size(); ++v) {
    const int u = index_[v];
    if (u >= 0) W.template middleRows<D>(u * D) = rigid_motion_in_local(poses[v]);
  }
  return W;
}

template <class Space>
void NormalEquations<Space>::anchor(Poses& poses) const {
  if (gauge_vertex_ < 0) return;
  const Pose T = Space::compose(graph_.poses[gauge_vertex_], Space::inverse(poses[gauge_vertex_]));
  for (auto& p : poses) p = Space::compose(T, p);
  poses[gauge_vertex_] = graph_.poses[gauge_vertex_];
}

template <class Space>
int NormalEquations<Space>::downweighted(const Poses& poses) const {
  if (kernel_.type == KernelType::kNone) return 0;
  int count = 0;
  for (size_t k = 0; k < graph_.edges.size(); ++k) {
    const auto& edge = graph_.edges[k];
    if (edge.kind != EdgeKind::kLoopClosure) continue;
    const typename Space::Vector e = Space::error(poses[edge.from], poses[edge.to], z_inv_[k]);
    if (kernel_.weight(e.dot(edge.information * e)) < 0.5) ++count;
  }
  return count;
}

template class NormalEquations<Se2>;
template class NormalEquations<Se3>;

}  // namespace kestrel::slam
