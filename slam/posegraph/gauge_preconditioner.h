#pragma once
// The preconditioner of the inexact steps (optimizer.cpp): the last factorisation of H, with
// the rigid motions of the graph at the poses where it was computed projected out on both
// sides, M^-1 = P H_0^-1 P with P the orthogonal projector off span(W_0).
//
// Why: with a free gauge H holds the rigid motion of the whole graph only by a weak prior
// (normal_equations.h), so H_0^-1 is about a million times larger along W_0 than elsewhere.
// Once the poses have moved, the new H is no longer that small along W_0, and H_0^-1 H has
// one huge eigenvalue per degree of freedom of the gauge, which conjugate gradients must
// first resolve (sphere2500, second step: plain, the residual was not down to 0.1 after the
// 6 iterations allowed and a factorisation followed; with the projection, 1 iteration).
// The rigid motion at the current poses needs no solving: the right-hand side has none (the
// cost does not change under it) and the optimiser takes out of the step whatever conjugate
// gradients leave along it (NormalEquations::remove_rigid_motion). Deflating it exactly as
// well (Saad et al. 2000) was tried and changed no iteration count on the benchmark graphs.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <utility>

namespace kestrel::slam {

class GaugePreconditioner {
 public:
  /// The rigid motions (one per column) at the poses of the new factorisation; no columns
  /// when the gauge is held by fixed vertices (then M^-1 = H_0^-1).
  void set_gauge(Eigen::MatrixXd W) {
    W_ = std::move(W);
    if (W_.cols() > 0) gram_.compute(W_.transpose() * W_);
  }

  /// P solve(P r), `solve` applying H_0^-1.
  template <class Solve>
  Eigen::VectorXd apply(const Solve& solve, const Eigen::VectorXd& r) const {
    if (W_.cols() == 0) return solve(r);
    Eigen::VectorXd z = solve(project(r));
    return project(z);
  }

 private:
  Eigen::VectorXd project(const Eigen::VectorXd& v) const {
    return v - W_ * gram_.solve(W_.transpose() * v);
  }

  Eigen::MatrixXd W_;
  Eigen::LDLT<Eigen::MatrixXd> gram_;
};

}  // namespace kestrel::slam
