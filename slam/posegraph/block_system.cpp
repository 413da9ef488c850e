#include "slam/posegraph/block_system.h"

#include <algorithm>
#include <stdexcept>

namespace kestrel::slam {

template <int D>
BlockSystem<D>::BlockSystem(int num_blocks, const std::vector<std::pair<int, int>>& pairs,
                            const std::vector<int>& block_order)
    : num_blocks_(num_blocks),
      diagonal_(num_blocks),
      slot_of_pair_(pairs.size()),
      position_(num_blocks, -1),
      diagonal_offset_(num_blocks),
      rhs_(Vector::Zero(static_cast<Eigen::Index>(num_blocks) * D)) {
  if (num_blocks <= 0) throw std::invalid_argument("BlockSystem: no unknowns");
  if (block_order.size() != static_cast<size_t>(num_blocks)) {
    throw std::invalid_argument("BlockSystem: the order must list every block once");
  }
  for (int k = 0; k < num_blocks; ++k) {
    const int b = block_order[static_cast<size_t>(k)];
    if (b < 0 || b >= num_blocks || position_[b] >= 0) {
      throw std::invalid_argument("BlockSystem: the order must list every block once");
    }
    position_[b] = k;
  }
  // The blocks above the diagonal of the permuted matrix, by column then row, without repeats.
  std::vector<std::pair<int, int>> upper;  // (col position, row position)
  upper.reserve(pairs.size());
  for (const auto& [a, b] : pairs) {
    if (a == b || a < 0 || b < 0 || a >= num_blocks || b >= num_blocks) {
      throw std::invalid_argument("BlockSystem: bad block pair");
    }
    upper.emplace_back(std::max(position_[a], position_[b]), std::min(position_[a], position_[b]));
  }
  std::vector<int> order(pairs.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::sort(order.begin(), order.end(), [&](int x, int y) { return upper[x] < upper[y]; });

  std::vector<int> count(num_blocks, 0);  // off-diagonal blocks per column position
  for (size_t r = 0; r < order.size(); ++r) {
    const auto& key = upper[order[r]];
    if (r == 0 || key != upper[order[r - 1]]) {
      const auto& [a, b] = pairs[static_cast<size_t>(order[r])];
      const int lo = std::min(a, b), hi = std::max(a, b);
      // The stored block is H(lo, hi); in the permuted upper triangle it lands transposed
      // when hi is eliminated before lo.
      slots_.push_back(Slot{lo, hi, key.second, key.first, count[key.first] * D, position_[lo] > position_[hi]});
      ++count[key.first];
    }
    slot_of_pair_[order[r]] = static_cast<int>(slots_.size()) - 1;
  }
  offdiagonal_.resize(slots_.size());

  // Column c*D+k (c a position) holds the D rows of each block above the diagonal, then rows
  // c*D..c*D+k.
  const int n = num_blocks * D;
  col_ptr_.assign(n + 1, 0);
  for (int c = 0; c < num_blocks; ++c) {
    diagonal_offset_[c] = count[c] * D;
    for (int k = 0; k < D; ++k) {
      col_ptr_[c * D + k + 1] = col_ptr_[c * D + k] + count[c] * D + k + 1;
    }
  }
  std::vector<int> row_idx(col_ptr_.back());
  for (const Slot& s : slots_) {
    for (int k = 0; k < D; ++k) {
      int* rows = row_idx.data() + col_ptr_[s.col * D + k] + s.offset;
      for (int a = 0; a < D; ++a) rows[a] = s.row * D + a;
    }
  }
  for (int c = 0; c < num_blocks; ++c) {
    for (int k = 0; k < D; ++k) {
      int* rows = row_idx.data() + col_ptr_[c * D + k] + diagonal_offset_[c];
      for (int a = 0; a <= k; ++a) rows[a] = c * D + a;
    }
  }
  // Already in elimination order: CHOLMOD factorises it as it is, without permuting the matrix
  // at every factorisation (a copy that cost as much as the factorisation on small graphs).
  cholesky_ = std::make_unique<SparseCholesky>(n, col_ptr_, std::move(row_idx), D, std::vector<int>{});
  set_zero();
}

template <int D>
void BlockSystem<D>::set_zero() {
  for (auto& b : diagonal_) b.setZero();
  for (auto& b : offdiagonal_) b.setZero();
  rhs_.setZero();
}

template <int D>
bool BlockSystem<D>::factorize(double lambda, double min_diagonal) {
  double* x = cholesky_->values();
  for (size_t s = 0; s < slots_.size(); ++s) {
    const Slot& slot = slots_[s];
    const Block& B = offdiagonal_[s];
    for (int k = 0; k < D; ++k) {
      double* dst = x + col_ptr_[slot.col * D + k] + slot.offset;
      if (slot.transposed) {
        for (int a = 0; a < D; ++a) dst[a] = B(k, a);
      } else {
        for (int a = 0; a < D; ++a) dst[a] = B(a, k);
      }
    }
  }
  for (int c = 0; c < num_blocks_; ++c) {
    const Block& B = diagonal_[c];
    const int p = position_[c];
    for (int k = 0; k < D; ++k) {
      double* dst = x + col_ptr_[p * D + k] + diagonal_offset_[p];
      for (int a = 0; a < k; ++a) dst[a] = B(a, k);
      dst[k] = B(k, k) + lambda * std::max(B(k, k), min_diagonal);
    }
  }
  return cholesky_->factorize();
}

template <int D>
typename BlockSystem<D>::Vector BlockSystem<D>::solve_factored(const Vector& b) const {
  return solve_factored(Eigen::MatrixXd(b)).col(0);
}

template <int D>
Eigen::MatrixXd BlockSystem<D>::solve_factored(const Eigen::MatrixXd& b) const {
  if (b.rows() != static_cast<Eigen::Index>(num_blocks_) * D) {
    throw std::invalid_argument("BlockSystem: right-hand side of the wrong size");
  }
  Eigen::MatrixXd x(b.rows(), b.cols());
  for (int c = 0; c < num_blocks_; ++c) x.middleRows<D>(position_[c] * D) = b.middleRows<D>(c * D);
  cholesky_->solve(x.data(), static_cast<int>(x.cols()));
  Eigen::MatrixXd out(b.rows(), b.cols());
  for (int c = 0; c < num_blocks_; ++c) out.middleRows<D>(c * D) = x.middleRows<D>(position_[c] * D);
  return out;
}

template <int D>
typename BlockSystem<D>::Vector BlockSystem<D>::multiply(const Vector& x, double lambda,
                                                         double min_diagonal) const {
  Vector y(x.size());
  for (int c = 0; c < num_blocks_; ++c) {
    const Block& B = diagonal_[c];
    const auto xc = x.template segment<D>(c * D);
    auto yc = y.template segment<D>(c * D);
    yc.noalias() = B.template selfadjointView<Eigen::Upper>() * xc;
    for (int k = 0; k < D; ++k) yc(k) += lambda * std::max(B(k, k), min_diagonal) * xc(k);
  }
  for (size_t s = 0; s < slots_.size(); ++s) {
    const Slot& slot = slots_[s];
    const Block& B = offdiagonal_[s];
    y.template segment<D>(slot.lo * D).noalias() += B * x.template segment<D>(slot.hi * D);
    y.template segment<D>(slot.hi * D).noalias() += B.transpose() * x.template segment<D>(slot.lo * D);
  }
  return y;
}

template <int D>
double BlockSystem<D>::damping_norm(const Vector& x, double min_diagonal) const {
  double sum = 0.0;
  for (int c = 0; c < num_blocks_; ++c) {
    for (int k = 0; k < D; ++k) {
      sum += std::max(diagonal_[c](k, k), min_diagonal) * x(c * D + k) * x(c * D + k);
    }
  }
  return sum;
}

template class BlockSystem<1>;
template class BlockSystem<2>;
template class BlockSystem<3>;
template class BlockSystem<6>;

}  // namespace kestrel::slam
