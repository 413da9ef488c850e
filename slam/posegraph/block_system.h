#pragma once
// The normal equations H x = b of a problem whose unknowns come in blocks of D (one block per
// free pose) and whose H is non-zero only on the diagonal blocks and on the blocks of pairs
// joined by an edge: assembled block by block, factorised with CHOLMOD.
//
// The pattern is fixed at construction (one symbolic analysis); between factorisations only
// the values change. The matrix handed to CHOLMOD is already permuted into the fill-reducing
// order, so that a factorisation does not first copy it into that order. Blocks are accumulated densely and scattered into the upper triangle in
// compressed-column form when factorising, with Levenberg-Marquardt damping added on the way.
// The last factorisation stays available while new values are accumulated, so that it can
// precondition later systems (multiply() and solve_factored()).

#include <Eigen/Core>
#include <Eigen/StdVector>
#include <memory>
#include <utility>
#include <vector>

#include "slam/posegraph/sparse_cholesky.h"

namespace kestrel::slam {

template <int D>
class BlockSystem {
 public:
  using Block = Eigen::Matrix<double, D, D>;
  using Vector = Eigen::VectorXd;

  /// `pairs` lists block pairs (a, b), a != b, in any order and possibly repeated;
  /// offdiagonal(k) is the block H(min(a, b), max(a, b)) of pair k. `block_order` is a
  /// fill-reducing order of the blocks (order_blocks()).
  BlockSystem(int num_blocks, const std::vector<std::pair<int, int>>& pairs,
              const std::vector<int>& block_order);

  int num_blocks() const { return num_blocks_; }
  /// Clears the accumulated H and b.
  void set_zero();
  Block& diagonal(int block) { return diagonal_[block]; }
  const Block& diagonal(int block) const { return diagonal_[block]; }
  Block& offdiagonal(int pair) { return offdiagonal_[slot_of_pair_[pair]]; }
  /// The right-hand side, D entries per block.
  Vector& rhs() { return rhs_; }
  const Vector& rhs() const { return rhs_; }

  /// Factorises H + lambda * diag(H) (each diagonal entry floored at `min_diagonal` before
  /// scaling); false if that matrix is not positive definite.
  bool factorize(double lambda = 0.0, double min_diagonal = 1e-6);
  /// Solves with the last factorisation: x = (H + damping)^-1 rhs().
  Vector solve() const { return solve_factored(rhs_); }
  /// Solves with the last factorisation for another right-hand side.
  Vector solve_factored(const Vector& b) const;
  /// Solves for several right-hand sides (the columns of `b`).
  Eigen::MatrixXd solve_factored(const Eigen::MatrixXd& b) const;
  /// (H + lambda * diag(H)) x with the blocks accumulated now.
  Vector multiply(const Vector& x, double lambda = 0.0, double min_diagonal = 1e-6) const;
  /// x' diag(H) x with the floor of factorize(): the damping's share of the quadratic model.
  double damping_norm(const Vector& x, double min_diagonal = 1e-6) const;

  double factor_flops() const { return cholesky_->factor_flops(); }
  double factor_nonzeros() const { return cholesky_->factor_nonzeros(); }

 private:
  struct Slot {
    int lo, hi;       ///< the blocks, lo < hi: the slot holds H(lo, hi)
    int row, col;     ///< their positions in elimination order, row < col
    int offset;       ///< position of the block's first row among the entries of each column
    bool transposed;  ///< H(lo, hi) lands transposed in the permuted upper triangle
  };
  int num_blocks_;
  std::vector<Block, Eigen::aligned_allocator<Block>> diagonal_;
  std::vector<Block, Eigen::aligned_allocator<Block>> offdiagonal_;
  std::vector<Slot> slots_;
  std::vector<int> slot_of_pair_;
  std::vector<int> position_;         ///< per block: its place in the elimination order
  std::vector<int> diagonal_offset_;  ///< per position: offset of its diagonal block in its columns
  std::vector<int> col_ptr_;
  Vector rhs_;
  std::unique_ptr<SparseCholesky> cholesky_;
};

}  // namespace kestrel::slam
