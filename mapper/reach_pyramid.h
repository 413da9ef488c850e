#pragma once
// The largest value over any pixel rectangle of an image, in a few lookups: for the cell
// search (scan_integrator.h), "does any ray in this cell's image reach past the cell?" is
// answered before any pixel or ray is looked at.
//
// Level L holds, for every pixel (u, v), the maximum over the square [u, u + 2^L) x
// [v, v + 2^L) clipped to the image (level 0 is the image). A rectangle whose shorter side is
// at least 2^L is covered exactly by overlapping level-L squares, about (w / 2^L) (h / 2^L) of
// them; the squares never reach outside the rectangle, so the answer is the exact maximum,
// not a bound. Building costs two vectorisable max passes per level over the image.
//
// Level kTileLevel at (4 ti, 4 tj) is the maximum over the 4x4 tile (ti, tj).

#include <algorithm>
#include <cstddef>
#include <vector>

namespace kestrel::mapper {

class ReachPyramid {
 public:
  static constexpr int kLevels = 4;  ///< squares of 1, 2, 4, 8 pixels

  /// Rebuilds from `values` (cols * rows, row-major); storage is reused between calls.
  void build(const float* values, int cols, int rows);
  /// The same in two steps, without copying the image: fill the returned level 0 (cols * rows,
  /// row-major; valid until the next call), then call build_levels().
  float* level0(int cols, int rows);
  void build_levels();

  int cols() const { return cols_; }
  int rows() const { return rows_; }

  /// Maximum over the square of side 2^level whose top-left pixel is (u, v), clipped.
  float square(int level, int u, int v) const {
    return levels_[static_cast<size_t>(level)][static_cast<size_t>(v) * cols_ + u];
  }

  /// True if some pixel in the inclusive rectangle [i0, i1] x [j0, j1] (non-empty, inside
  /// the image) holds a value >= threshold; stops at the first square that does.
  bool any_at_least(int i0, int i1, int j0, int j1, float threshold) const;

  /// The maximum over the rectangle (non-empty, inside the image).
  float max_over(int i0, int i1, int j0, int j1) const;

 private:
  int level_for(int w, int h) const;

  int cols_ = 0, rows_ = 0;
  std::vector<float> levels_[kLevels];
  std::vector<float> scratch_;
};

inline int ReachPyramid::level_for(int w, int h) const {
  const unsigned shorter = static_cast<unsigned>(std::min(w, h));
  const int level = 31 - __builtin_clz(shorter);  // floor(log2(shorter)), shorter >= 1
  return std::min(level, kLevels - 1);
}

inline bool ReachPyramid::any_at_least(int i0, int i1, int j0, int j1, float threshold) const {
  const int level = level_for(i1 - i0 + 1, j1 - j0 + 1);
  const int side = 1 << level;
  const int u_last = i1 - side + 1, v_last = j1 - side + 1;
  const float* values = levels_[static_cast<size_t>(level)].data();
  for (int v = j0;; v = std::min(v + side, v_last)) {
    const float* row = values + static_cast<size_t>(v) * cols_;
    for (int u = i0;; u = std::min(u + side, u_last)) {
      if (row[u] >= threshold) return true;
      if (u == u_last) break;
    }
    if (v == v_last) break;
  }
  return false;
}

}  // namespace kestrel::mapper
