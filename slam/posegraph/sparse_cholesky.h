#pragma once
// Sparse Cholesky factorisation of a symmetric positive-definite matrix with CHOLMOD
// (SuiteSparse): symbolic analysis once per sparsity pattern, then numeric factorisations and
// solves as often as the values change.
//
// The matrix is given as its upper triangle (diagonal included) in compressed-column form,
// rows sorted within each column. The fill-reducing ordering comes from the caller, computed
// once on the graph of unknowns (order_blocks below): ordering a pose graph by blocks is as
// good as ordering the scalar matrix and far cheaper, and the same ordering serves every
// system built on the graph.

#include <memory>
#include <utility>
#include <vector>

namespace kestrel::slam {

/// A fill-reducing order of `num_blocks` unknowns coupled by `pairs`: order[k] is the block
/// eliminated k-th. CHOLMOD's AMD, with METIS tried too when AMD fills in badly.
std::vector<int> order_blocks(int num_blocks, const std::vector<std::pair<int, int>>& pairs);

class SparseCholesky {
 public:
  /// `col_ptr` (n + 1 entries) and `row_idx` describe the upper triangle; every column holds
  /// its diagonal. `block_order` (from order_blocks) orders blocks of `block_size` unknowns;
  /// n must be a multiple of `block_size`. An empty `block_order` means the matrix is already
  /// in elimination order (it is then factorised without any permutation).
  SparseCholesky(int n, std::vector<int> col_ptr, std::vector<int> row_idx, int block_size,
                 const std::vector<int>& block_order);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  int size() const;
  /// The values of the matrix, in the order of row_idx; write them before factorize().
  double* values();
  /// Factorises the current values; false if the matrix is not positive definite.
  bool factorize();
  /// Solves A x = b with the last factorisation for `nrhs` right-hand sides stored column
  /// after column (n each), in place.
  void solve(double* b, int nrhs = 1) const;
  /// Floating-point operations of one factorisation and non-zeros of the factor (from the
  /// symbolic analysis), to weigh a new factorisation against more solves.
  double factor_flops() const;
  double factor_nonzeros() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace kestrel::slam
