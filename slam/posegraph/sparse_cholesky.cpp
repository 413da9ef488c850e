#include "slam/posegraph/sparse_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace kestrel::slam {
// Named rather than anonymous: Impl below holds a Common, and GCC warns about a class with a
// member of an anonymous-namespace type whenever this file is compiled inside another
// (the unity build, CMakeLists.txt).
namespace cholmod_glue {

struct Common {
  cholmod_common c;
  Common() {
    cholmod_start(&c);
    c.print = 0;  // a matrix that is not positive definite is reported through factorize()
  }
  ~Common() { cholmod_finish(&c); }
  Common(const Common&) = delete;
  Common& operator=(const Common&) = delete;
};

}  // namespace cholmod_glue
using cholmod_glue::Common;

std::vector<int> order_blocks(int num_blocks, const std::vector<std::pair<int, int>>& pairs) {
  if (num_blocks <= 0) return {};
  // Upper triangle of the block pattern (diagonal included), column by column.
  std::vector<std::pair<int, int>> entries;  // (col, row), row <= col
  entries.reserve(pairs.size() + num_blocks);
  for (const auto& [a, b] : pairs) entries.emplace_back(std::max(a, b), std::min(a, b));
  for (int k = 0; k < num_blocks; ++k) entries.emplace_back(k, k);
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());

  Common common;
  cholmod_sparse* G = cholmod_allocate_sparse(num_blocks, num_blocks, entries.size(), 1, 1, 1,
                                              CHOLMOD_PATTERN, &common.c);
  if (G == nullptr) throw std::bad_alloc();
  int* p = static_cast<int*>(G->p);
  int* i = static_cast<int*>(G->i);
  std::fill_n(p, num_blocks + 1, 0);
  for (size_t k = 0; k < entries.size(); ++k) {
    ++p[entries[k].first + 1];
    i[k] = entries[k].second;
  }
  for (int c = 0; c < num_blocks; ++c) p[c + 1] += p[c];
  common.c.nmethods = 0;  // AMD; METIS too when AMD fills in badly; the best is kept
  cholmod_factor* F = cholmod_analyze(G, &common.c);
  cholmod_free_sparse(&G, &common.c);
  if (F == nullptr) throw std::runtime_error("CHOLMOD could not order the pose graph");
  const int* perm = static_cast<const int*>(F->Perm);
  std::vector<int> order(perm, perm + num_blocks);
  cholmod_free_factor(&F, &common.c);
  return order;
}

struct SparseCholesky::Impl {
  Common common;
  cholmod_sparse* A = nullptr;
  cholmod_factor* L = nullptr;
  // Solve workspaces, reused across calls (solve() is logically const).
  mutable cholmod_dense* B = nullptr;
  mutable cholmod_dense* X = nullptr;
  mutable cholmod_dense* Y = nullptr;
  mutable cholmod_dense* E = nullptr;
  int n = 0;
  double flops = 0.0;
  double nonzeros = 0.0;

  ~Impl() {
    cholmod_common* c = &common.c;
    cholmod_free_dense(&B, c);
    cholmod_free_dense(&X, c);
    cholmod_free_dense(&Y, c);
    cholmod_free_dense(&E, c);
    cholmod_free_factor(&L, c);
    cholmod_free_sparse(&A, c);
  }
};

SparseCholesky::SparseCholesky(int n, std::vector<int> col_ptr, std::vector<int> row_idx,
                               int block_size, const std::vector<int>& block_order)
    : impl_(std::make_unique<Impl>()) {
  if (n <= 0 || block_size <= 0 || n % block_size != 0 ||
      col_ptr.size() != static_cast<size_t>(n) + 1 ||
      row_idx.size() != static_cast<size_t>(col_ptr.back()) ||
      (!block_order.empty() && block_order.size() != static_cast<size_t>(n / block_size))) {
    throw std::invalid_argument("SparseCholesky: inconsistent pattern or ordering");
  }
  Impl& m = *impl_;
  cholmod_common* c = &m.common.c;
  m.n = n;
  m.A = cholmod_allocate_sparse(n, n, row_idx.size(), 1, 1, 1, CHOLMOD_REAL, c);
  if (m.A == nullptr) throw std::bad_alloc();
  std::memcpy(m.A->p, col_ptr.data(), col_ptr.size() * sizeof(int));
  std::memcpy(m.A->i, row_idx.data(), row_idx.size() * sizeof(int));
  std::fill_n(static_cast<double*>(m.A->x), row_idx.size(), 0.0);

  c->nmethods = 1;
  if (block_order.empty()) {
    // The caller ordered the matrix already: no permutation, and no postorder (which would
    // bring one back).
    c->method[0].ordering = CHOLMOD_NATURAL;
    c->postorder = 0;
    m.L = cholmod_analyze(m.A, c);
  } else {
    std::vector<int> perm(n);
    for (size_t b = 0; b < block_order.size(); ++b) {
      for (int k = 0; k < block_size; ++k) perm[b * block_size + k] = block_order[b] * block_size + k;
    }
    c->method[0].ordering = CHOLMOD_GIVEN;
    c->postorder = 1;
    m.L = cholmod_analyze_p(m.A, perm.data(), nullptr, 0, c);
  }
  if (m.L == nullptr) throw std::runtime_error("CHOLMOD symbolic analysis failed");
  m.flops = c->fl;
  m.nonzeros = c->lnz;
}

SparseCholesky::~SparseCholesky() = default;

int SparseCholesky::size() const { return impl_->n; }

double* SparseCholesky::values() { return static_cast<double*>(impl_->A->x); }

bool SparseCholesky::factorize() {
  Impl& m = *impl_;
  cholmod_factorize(m.A, m.L, &m.common.c);
  if (m.common.c.status != CHOLMOD_OK || m.L->minor != m.L->n) return false;
  if (!m.L->is_super && !m.L->is_ll) {
    // A simplicial LDL' factorisation succeeds on indefinite matrices: D must be positive.
    const int* p = static_cast<const int*>(m.L->p);
    const double* x = static_cast<const double*>(m.L->x);
    for (size_t j = 0; j < m.L->n; ++j) {
      if (!(x[p[j]] > 0.0)) return false;
    }
  }
  return true;
}

void SparseCholesky::solve(double* b, int nrhs) const {
  Impl& m = *impl_;
  cholmod_common* c = &m.common.c;
  if (m.B == nullptr || static_cast<int>(m.B->ncol) != nrhs) {
    cholmod_free_dense(&m.B, c);
    m.B = cholmod_allocate_dense(m.n, nrhs, m.n, CHOLMOD_REAL, c);
    if (m.B == nullptr) throw std::bad_alloc();
  }
  const size_t count = static_cast<size_t>(m.n) * static_cast<size_t>(nrhs);
  std::memcpy(m.B->x, b, sizeof(double) * count);
  if (!cholmod_solve2(CHOLMOD_A, m.L, m.B, nullptr, &m.X, nullptr, &m.Y, &m.E, c)) {
    throw std::runtime_error("CHOLMOD solve failed");
  }
  std::memcpy(b, m.X->x, sizeof(double) * count);
}

double SparseCholesky::factor_flops() const { return impl_->flops; }
double SparseCholesky::factor_nonzeros() const { return impl_->nonzeros; }

}  // namespace kestrel::slam
