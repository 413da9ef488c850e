#include "mapper/reach_pyramid.h"

#include <algorithm>
#include <cstring>

namespace kestrel::mapper {

void ReachPyramid::build(const float* values, int cols, int rows) {
  float* image = level0(cols, rows);
  const size_t n = static_cast<size_t>(cols) * static_cast<size_t>(rows);
  if (n > 0) std::memcpy(image, values, n * sizeof(float));
  build_levels();
}

float* ReachPyramid::level0(int cols, int rows) {
  cols_ = cols;
  rows_ = rows;
  const size_t n = static_cast<size_t>(cols) * static_cast<size_t>(rows);
  for (std::vector<float>& level : levels_) level.resize(n);
  scratch_.resize(n);
  return levels_[0].data();
}

void ReachPyramid::build_levels() {
  const int cols = cols_, rows = rows_;
  const size_t n = static_cast<size_t>(cols) * static_cast<size_t>(rows);
  if (n == 0) return;
  for (int level = 1; level < kLevels; ++level) {
    const int half = 1 << (level - 1);
    const float* in = levels_[level - 1].data();
    float* across = scratch_.data();
    // Across: [u, u + 2 half) is [u, u + half) and [u + half, u + 2 half), the second
    // clipped away (already covered by the first) near the right edge.
    const int inner_cols = std::max(0, cols - half);
    for (int v = 0; v < rows; ++v) {
      const float* a = in + static_cast<size_t>(v) * cols;
      float* o = across + static_cast<size_t>(v) * cols;
      for (int u = 0; u < inner_cols; ++u) o[u] = std::max(a[u], a[u + half]);
      for (int u = inner_cols; u < cols; ++u) o[u] = a[u];
    }
    // Down, the same along the columns.
    float* out = levels_[level].data();
    const int inner_rows = std::max(0, rows - half);
    const size_t shift = static_cast<size_t>(half) * cols;
    const size_t inner = static_cast<size_t>(inner_rows) * cols;
    for (size_t i = 0; i < inner; ++i) out[i] = std::max(across[i], across[i + shift]);
    std::memcpy(out + inner, across + inner, (n - inner) * sizeof(float));
  }
}

float ReachPyramid::max_over(int i0, int i1, int j0, int j1) const {
  const int level = level_for(i1 - i0 + 1, j1 - j0 + 1);
  const int side = 1 << level;
  const int u_last = i1 - side + 1, v_last = j1 - side + 1;
  const float* values = levels_[static_cast<size_t>(level)].data();
  float best = values[static_cast<size_t>(j0) * cols_ + i0];
  for (int v = j0;; v = std::min(v + side, v_last)) {
    const float* row = values + static_cast<size_t>(v) * cols_;
    for (int u = i0;; u = std::min(u + side, u_last)) {
      best = std::max(best, row[u]);
      if (u == u_last) break;
    }
    if (v == v_last) break;
  }
  return best;
}

}  // namespace kestrel::mapper
