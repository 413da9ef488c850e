#include "vo/fast.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::vo {
namespace {

// The radius-3 Bresenham circle, clockwise from the top.
constexpr std::array<std::array<int, 2>, 16> kCircle{{{0, -3}, {1, -3}, {2, -2}, {3, -1},
                                                       {3, 0}, {3, 1}, {2, 2}, {1, 3},
                                                       {0, 3}, {-1, 3}, {-2, 2}, {-3, 1},
                                                       {-3, 0}, {-3, -1}, {-2, -2}, {-1, -3}}};

std::array<int, 16> circle_offsets(int stride) {
  std::array<int, 16> off{};
  for (size_t k = 0; k < 16; ++k) off[k] = kCircle[k][0] + kCircle[k][1] * stride;
  return off;
}

// True if 9 contiguous bits of the 16-bit circular mask are set.
inline bool has_arc9(uint32_t mask) {
  uint32_t m = mask | (mask << 16);  // unroll the circle so that arcs wrap
  m &= m >> 1;                        // runs of 2
  m &= m >> 2;                        // runs of 4
  m &= m >> 4;                        // runs of 8
  m &= m >> 1;                        // runs of 9
  return (m & 0xFFFFu) != 0;
}

inline bool is_corner_scalar(const uint8_t* p, const std::array<int, 16>& off, int t) {
  const int c = *p;
  const int hi = c + t;
  const int lo = c - t;
  // Necessary condition: two neighbouring compass points on the same side.
  const int n = p[off[0]], e = p[off[4]], s = p[off[8]], w = p[off[12]];
  const int bright = (n > hi) | ((e > hi) << 1) | ((s > hi) << 2) | ((w > hi) << 3);
  const int dark = (n < lo) | ((e < lo) << 1) | ((s < lo) << 2) | ((w < lo) << 3);
  auto adjacent_pair = [](int m) { return (m & (m >> 1)) != 0 || (m & 9) == 9; };
  if (!adjacent_pair(bright) && !adjacent_pair(dark)) return false;
  uint32_t bmask = 0, dmask = 0;
  for (int k = 0; k < 16; ++k) {
    const int v = p[off[static_cast<size_t>(k)]];
    bmask |= static_cast<uint32_t>(v > hi) << k;
    dmask |= static_cast<uint32_t>(v < lo) << k;
  }
  return has_arc9(bmask) || has_arc9(dmask);
}

// Finds the corners of row y and writes their columns and scores; returns how many.
using RowDetector = int (*)(const uint8_t* row, int width, int stride, int threshold,
                            const std::array<int, 16>& off, int16_t* columns, uint8_t* scores);

int detect_row_scalar(const uint8_t* row, int width, int stride, int threshold,
                      const std::array<int, 16>& off, int16_t* columns, uint8_t* scores) {
  int n = 0;
  for (int x = 3; x < width - 3; ++x) {
    if (!is_corner_scalar(row + x, off, threshold)) continue;
    columns[n++] = static_cast<int16_t>(x);
    scores[x] = static_cast<uint8_t>(fast9_score(row + x, stride));
  }
  return n;
}

#if defined(__SSE2__)
// Per byte lane: the largest, over the 16 arcs of 9 contiguous circle pixels, of the arc's
// minimum of x_k (sliding minima over 2, 4, 8, then 9; the circle wraps).
inline __m128i best_arc9(const __m128i (&x)[16]) {
  __m128i m2[16], m4[16];
  for (int k = 0; k < 16; ++k) m2[k] = _mm_min_epu8(x[k], x[(k + 1) & 15]);
  for (int k = 0; k < 16; ++k) m4[k] = _mm_min_epu8(m2[k], m2[(k + 2) & 15]);
  __m128i best = _mm_setzero_si128();
  for (int k = 0; k < 16; ++k) {
    const __m128i m8 = _mm_min_epu8(m4[k], m4[(k + 4) & 15]);
    best = _mm_max_epu8(best, _mm_min_epu8(m8, x[(k + 8) & 15]));
  }
  return best;
}

int detect_row_sse2(const uint8_t* row, int width, int stride, int threshold,
                    const std::array<int, 16>& off, int16_t* columns, uint8_t* scores) {
  // The bounds centre +- t are formed with unsigned saturation (nothing is brighter than 255
  // or darker than 0, as in the scalar test, for any t up to 254); bytes are then compared as
  // signed after flipping the top bit, SSE2 having no unsigned byte comparison.
  const __m128i flip = _mm_set1_epi8(static_cast<char>(0x80));
  const __m128i t = _mm_set1_epi8(static_cast<char>(static_cast<uint8_t>(threshold)));
  const __m128i one = _mm_set1_epi8(1);
  int n = 0;
  int x = 3;
  for (; x + 16 <= width - 3; x += 16) {
    const uint8_t* p = row + x;
    const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    const __m128i hi = _mm_xor_si128(_mm_adds_epu8(c, t), flip);
    const __m128i lo = _mm_xor_si128(_mm_subs_epu8(c, t), flip);
    auto load = [&](int k) {
      return _mm_xor_si128(
          _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + off[static_cast<size_t>(k)])),
          flip);
    };
    const __m128i a0 = load(0), a4 = load(4), a8 = load(8), a12 = load(12);
    const __m128i b0 = _mm_cmpgt_epi8(a0, hi), b4 = _mm_cmpgt_epi8(a4, hi);
    const __m128i b8 = _mm_cmpgt_epi8(a8, hi), b12 = _mm_cmpgt_epi8(a12, hi);
    const __m128i d0 = _mm_cmpgt_epi8(lo, a0), d4 = _mm_cmpgt_epi8(lo, a4);
    const __m128i d8 = _mm_cmpgt_epi8(lo, a8), d12 = _mm_cmpgt_epi8(lo, a12);
    __m128i m = _mm_or_si128(_mm_or_si128(_mm_and_si128(b0, b4), _mm_and_si128(b4, b8)),
                             _mm_or_si128(_mm_and_si128(b8, b12), _mm_and_si128(b12, b0)));
    m = _mm_or_si128(m, _mm_or_si128(_mm_or_si128(_mm_and_si128(d0, d4), _mm_and_si128(d4, d8)),
                                     _mm_or_si128(_mm_and_si128(d8, d12), _mm_and_si128(d12, d0))));
    if (_mm_movemask_epi8(m) == 0) continue;

    // The score of all 16 pixels at once, in unsigned bytes: with b_k = max(circle_k - c, 0)
    // and d_k = max(c - circle_k, 0) (saturating subtractions), the best arc's
    // max(min b, min d) is fast9_score() + 1, and the pixel is a corner exactly when that
    // exceeds the threshold (circle_k > c + t with c + t saturated at 255 is circle_k - c > t).
    __m128i v[16];
    for (int k = 0; k < 16; ++k)
      v[k] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + off[static_cast<size_t>(k)]));
    __m128i side[16];
    for (int k = 0; k < 16; ++k) side[k] = _mm_subs_epu8(v[k], c);
    const __m128i best_b = best_arc9(side);
    for (int k = 0; k < 16; ++k) side[k] = _mm_subs_epu8(c, v[k]);
    const __m128i best = _mm_max_epu8(best_b, best_arc9(side));
    const __m128i not_corner = _mm_cmpeq_epi8(_mm_subs_epu8(best, t), _mm_setzero_si128());
    int bits = ~_mm_movemask_epi8(not_corner) & 0xFFFF;
    if (bits == 0) continue;
    // Scores (best - 1) of the corners, 0 elsewhere, as the non-maximum suppression expects.
    _mm_storeu_si128(reinterpret_cast<__m128i*>(scores + x),
                     _mm_andnot_si128(not_corner, _mm_sub_epi8(best, one)));
    while (bits != 0) {
      const int i = __builtin_ctz(static_cast<unsigned>(bits));
      bits &= bits - 1;
      columns[n++] = static_cast<int16_t>(x + i);
    }
  }
  for (; x < width - 3; ++x) {
    if (!is_corner_scalar(row + x, off, threshold)) continue;
    columns[n++] = static_cast<int16_t>(x);
    scores[x] = static_cast<uint8_t>(fast9_score(row + x, stride));
  }
  return n;
}
#endif

void detect(const cv::Mat& image, int threshold, bool nonmax, std::vector<FastCorner>& corners,
            FastScratch& scratch, RowDetector detect_row) {
  if (image.type() != CV_8UC1) throw std::invalid_argument("detect_fast9: image must be CV_8UC1");
  if (threshold < 1 || threshold > 254)
    throw std::invalid_argument("detect_fast9: threshold must be in 1..254");
  corners.clear();
  const int w = image.cols, h = image.rows;
  if (w < 7 || h < 7) return;
  const int stride = static_cast<int>(image.step[0]);
  const auto off = circle_offsets(stride);
  const size_t ws = static_cast<size_t>(w);
  scratch.scores.assign(3 * ws, 0);
  scratch.columns.resize(3 * ws);
  scratch.counts.assign(3, 0);
  auto scores_of = [&](int y) { return scratch.scores.data() + static_cast<size_t>(y % 3) * ws; };
  auto columns_of = [&](int y) { return scratch.columns.data() + static_cast<size_t>(y % 3) * ws; };

  // Row y's corners are final once the scores of rows y - 1 and y + 1 are known.
  auto emit_row = [&](int y) {
    const int count = scratch.counts[static_cast<size_t>(y % 3)];
    const uint8_t* above = scores_of(y + 2);  // (y - 1) mod 3
    const uint8_t* here = scores_of(y);
    const uint8_t* below = scores_of(y + 1);
    const int16_t* cols = columns_of(y);
    for (int i = 0; i < count; ++i) {
      const int x = cols[i];
      const int s = here[x];
      if (nonmax && !(s > here[x - 1] && s > here[x + 1] && s > above[x - 1] && s > above[x] &&
                      s > above[x + 1] && s > below[x - 1] && s > below[x] && s > below[x + 1]))
        continue;
      corners.push_back({static_cast<int16_t>(x), static_cast<int16_t>(y), static_cast<int16_t>(s)});
    }
  };

  for (int y = 3; y <= h - 3; ++y) {
    uint8_t* sc = scores_of(y);
    std::fill(sc, sc + w, uint8_t{0});
    int count = 0;
    if (y < h - 3) count = detect_row(image.ptr<uint8_t>(y), w, stride, threshold, off, columns_of(y), sc);
    scratch.counts[static_cast<size_t>(y % 3)] = count;
    if (y > 3) emit_row(y - 1);
  }
}

}  // namespace

int fast9_score(const uint8_t* p, int stride) {
  const auto off = circle_offsets(stride);
  const int c = *p;
  std::array<int, 25> d{};
  for (size_t k = 0; k < 25; ++k) d[k] = p[off[k & 15]] - c;
  // Sliding minimum / maximum over windows of 9: pairs, quads, eights, then nine.
  int best = 0;
  std::array<int, 24> mn2{}, mx2{};
  for (size_t k = 0; k < 24; ++k) {
    mn2[k] = std::min(d[k], d[k + 1]);
    mx2[k] = std::max(d[k], d[k + 1]);
  }
  for (size_t k = 0; k < 16; ++k) {
    const int mn4a = std::min(mn2[k], mn2[k + 2]), mn4b = std::min(mn2[k + 4], mn2[k + 6]);
    const int mx4a = std::max(mx2[k], mx2[k + 2]), mx4b = std::max(mx2[k + 4], mx2[k + 6]);
    const int arc_min = std::min(std::min(mn4a, mn4b), d[k + 8]);  // all brighter by >= this
    const int arc_max = std::max(std::max(mx4a, mx4b), d[k + 8]);  // all darker by >= -this
    best = std::max(best, std::max(arc_min, -arc_max));
  }
  return best - 1;
}

void detect_fast9(const cv::Mat& image, int threshold, bool nonmax_suppression,
                  std::vector<FastCorner>& corners, FastScratch& scratch) {
#if defined(__SSE2__)
  detect(image, threshold, nonmax_suppression, corners, scratch, detect_row_sse2);
#else
  detect(image, threshold, nonmax_suppression, corners, scratch, detect_row_scalar);
#endif
}

void detect_fast9_scalar(const cv::Mat& image, int threshold, bool nonmax_suppression,
                         std::vector<FastCorner>& corners, FastScratch& scratch) {
  detect(image, threshold, nonmax_suppression, corners, scratch, detect_row_scalar);
}

}  // namespace kestrel::vo
