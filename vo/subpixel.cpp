#include "vo/subpixel.h"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::vo {
namespace {

constexpr int kMaxWindow = 15;
constexpr int kMaxSide = kMaxWindow + 2;
using Patch = std::array<float, kMaxSide * kMaxSide>;

// The first w (>= 4) bytes of `in` as floats (exact).
template <int w>
inline void to_float_row(const uint8_t* in, float* out) {
  static_assert(w >= 4, "blocks of four");
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  for (int k = 0; k < w; k += 4) {
    const int o = k + 4 <= w ? k : w - 4;  // the last block overlaps instead of reading past w
    int32_t v;
    std::memcpy(&v, in + o, 4);
    const __m128i b = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(v), zero), zero);
    _mm_storeu_ps(out + o, _mm_cvtepi32_ps(b));
  }
#else
  for (int x = 0; x < w; ++x) out[x] = float(in[x]);
#endif
}

// The normal equations of J = (gx, gy, -1) with the ESM gradient (both images' central
// differences averaged) over the window, and the cost.
struct NormalSums {
  float hxx = 0, hxy = 0, hyy = 0, sx = 0, sy = 0, ex = 0, ey = 0, se = 0, cost = 0;
  /// One pixel's terms: gradient (gx, gy) and residual e.
  void add(float gx, float gy, float e) {
    hxx += gx * gx;
    hxy += gx * gy;
    hyy += gy * gy;
    sx += gx;
    sy += gy;
    ex += gx * e;
    ey += gy * e;
    se += e;
    cost += e * e;
  }
};

// The reference: one pass, every sum in pixel (raster) order, as scalars the compiler keeps in
// registers.
template <int window>
NormalSums accumulate_scalar(const Patch& s, const Patch& t, const Patch& tgx, const Patch& tgy, float bias) {
  constexpr int side = window + 2;
  constexpr size_t sd = static_cast<size_t>(side);
  NormalSums a;
  for (int y = 1; y <= window; ++y) {
    for (int x = 1; x <= window; ++x) {
      const size_t i = static_cast<size_t>(y * side + x);
      const float gx = 0.25f * (s[i + 1] - s[i - 1] + tgx[i]);
      const float gy = 0.25f * (s[i + sd] - s[i - sd] + tgy[i]);
      const float e = s[i] - t[i] - bias;
      a.add(gx, gy, e);
    }
  }
  return a;
}

#if defined(__SSE2__)
// The same sums, bit for bit: gx, gy and e of all pixels first (element-wise, vectorised),
// then four pixels at a time: their eight products and terms transposed so that each lane of
// two accumulators holds one sum, which then receives the four pixels' terms one after the
// other, in raster order as in the scalar loop (SSE2 has no fused multiply-add to round
// differently).
template <int window>
NormalSums accumulate(const Patch& s, const Patch& t, const Patch& tgx, const Patch& tgy, float bias) {
  constexpr int side = window + 2;
  constexpr size_t sd = static_cast<size_t>(side);
  constexpr int n = window * window;
  alignas(16) float gxa[n], gya[n], ea[n];
  for (int y = 1; y <= window; ++y) {
    for (int x = 1; x <= window; ++x) {
      const size_t i = static_cast<size_t>(y * side + x);
      const size_t k = static_cast<size_t>((y - 1) * window + (x - 1));
      gxa[k] = 0.25f * (s[i + 1] - s[i - 1] + tgx[i]);
      gya[k] = 0.25f * (s[i + sd] - s[i - sd] + tgy[i]);
      ea[k] = s[i] - t[i] - bias;
    }
  }
  __m128 h = _mm_setzero_ps();  // hxx, hxy, hyy, sx
  __m128 g = _mm_setzero_ps();  // sy, ex, ey, se
  float cost = 0.0f;
  int p = 0;
  for (; p + 4 <= n; p += 4) {
    const __m128 gx = _mm_load_ps(gxa + p), gy = _mm_load_ps(gya + p), e = _mm_load_ps(ea + p);
    __m128 h0 = _mm_mul_ps(gx, gx), h1 = _mm_mul_ps(gx, gy), h2 = _mm_mul_ps(gy, gy), h3 = gx;
    _MM_TRANSPOSE4_PS(h0, h1, h2, h3);  // h_j: pixel p + j's (gx gx, gx gy, gy gy, gx)
    h = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_add_ps(h, h0), h1), h2), h3);
    __m128 g0 = gy, g1 = _mm_mul_ps(gx, e), g2 = _mm_mul_ps(gy, e), g3 = e;
    _MM_TRANSPOSE4_PS(g0, g1, g2, g3);  // g_j: pixel p + j's (gy, gx e, gy e, e)
    g = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_add_ps(g, g0), g1), g2), g3);
    alignas(16) float ee[4];
    _mm_store_ps(ee, _mm_mul_ps(e, e));
    cost += ee[0];
    cost += ee[1];
    cost += ee[2];
    cost += ee[3];
  }
  alignas(16) float hs[4], gs[4];
  _mm_store_ps(hs, h);
  _mm_store_ps(gs, g);
  NormalSums a;
  a.hxx = hs[0];
  a.hxy = hs[1];
  a.hyy = hs[2];
  a.sx = hs[3];
  a.sy = gs[0];
  a.ex = gs[1];
  a.ey = gs[2];
  a.se = gs[3];
  a.cost = cost;
  for (; p < n; ++p) {
    a.add(gxa[p], gya[p], ea[p]);
  }
  return a;
}
#else
template <int window>
NormalSums accumulate(const Patch& s, const Patch& t, const Patch& tgx, const Patch& tgy, float bias) {
  return accumulate_scalar<window>(s, t, tgx, tgy, bias);
}
#endif

// The refinement for a window size known at compile time, so that every loop has a fixed
// trip count (unrolled and vectorised; the arithmetic and its order are those of the source).
template <int window, bool simd>
SubpixelResult refine(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                      const Eigen::Vector2f& cur_start, float max_shift, int max_iterations) {
  SubpixelResult result;
  result.position = cur_start;
  constexpr int r = window / 2;
  constexpr int side = window + 2;  // one extra pixel on each side for central differences
  constexpr int half = r + 1;
  if (ref_px.x() - half < 0 || ref_px.y() - half < 0 || ref_px.x() + half >= ref.cols ||
      ref_px.y() + half >= ref.rows)
    return result;

  // No zero-initialisation of the patches (4.6 KB per call): every element read is written
  // first (t and s whole, the gradients on the interior 1..window, the only part read).
  Patch t;
  for (int y = 0; y < side; ++y)
    to_float_row<side>(ref.ptr<uint8_t>(ref_px.y() - half + y) + (ref_px.x() - half), t.data() + y * side);

  // The template's half of the gradients does not change between iterations.
  Patch tgx, tgy;
  constexpr size_t sd = static_cast<size_t>(side);
  for (int y = 1; y <= window; ++y) {
    for (int x = 1; x <= window; ++x) {
      const size_t i = static_cast<size_t>(y * side + x);
      tgx[i] = t[i + 1] - t[i - 1];
      tgy[i] = t[i + sd] - t[i - sd];
    }
  }

  Eigen::Vector2f pos = cur_start;
  float bias = 0.0f;
  Patch s;
  for (int it = 0; it < max_iterations; ++it) {
    const float ox = pos.x() - float(half), oy = pos.y() - float(half);
    const int x0 = static_cast<int>(std::floor(ox)), y0 = static_cast<int>(std::floor(oy));
    if (x0 < 0 || y0 < 0 || x0 + side >= cur.cols || y0 + side >= cur.rows) return result;
    // Every sample shares the same fractional offset, hence the same bilinear weights.
    const float ax = ox - float(x0), ay = oy - float(y0);
    const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
    if (simd) {
      // The side + 1 image rows as floats once (each serves two output rows), then the same
      // expression on floats, which vectorises (the byte loads and conversions did not).
      float rows[side + 1][side + 1];
      for (int y = 0; y <= side; ++y) to_float_row<side + 1>(cur.ptr<uint8_t>(y0 + y) + x0, rows[y]);
      for (int y = 0; y < side; ++y) {
        const float* r0 = rows[y];
        const float* r1 = rows[y + 1];
        for (int x = 0; x < side; ++x)
          s[static_cast<size_t>(y * side + x)] = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
      }
    } else {
      for (int y = 0; y < side; ++y) {
        const uint8_t* r0 = cur.ptr<uint8_t>(y0 + y) + x0;
        const uint8_t* r1 = cur.ptr<uint8_t>(y0 + y + 1) + x0;
        for (int x = 0; x < side; ++x)
          s[static_cast<size_t>(y * side + x)] = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
      }
    }
    const NormalSums a = simd ? accumulate<window>(s, t, tgx, tgy, bias)
                              : accumulate_scalar<window>(s, t, tgx, tgy, bias);
    const float hxx = a.hxx, hxy = a.hxy, hyy = a.hyy, sx = a.sx, sy = a.sy, ex = a.ex, ey = a.ey,
                se = a.se, cost = a.cost;
    constexpr float n = float(window * window);
    result.rms_error = std::sqrt(cost / n);
    Eigen::Matrix3f H;
    H << hxx, hxy, -sx, hxy, hyy, -sy, -sx, -sy, n;
    const Eigen::Vector3f g(ex, ey, -se);
    const Eigen::Vector3f delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) return result;
    pos += delta.head<2>();
    bias += delta(2);
    result.iterations = it + 1;
    if ((pos - cur_start).norm() > max_shift) return result;
    if (delta.head<2>().squaredNorm() < 1e-4f) break;
  }
  result.position = pos;
  result.ok = true;
  return result;
}

template <bool simd>
SubpixelResult refine_any(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                          const Eigen::Vector2f& cur_start, int window, float max_shift,
                          int max_iterations) {
  static_assert(kMaxWindow == 15, "one instantiation per odd window 3..kMaxWindow");
  switch (window) {
    case 3: return refine<3, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 5: return refine<5, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 7: return refine<7, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 9: return refine<9, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 11: return refine<11, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 13: return refine<13, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    case 15: return refine<15, simd>(ref, ref_px, cur, cur_start, max_shift, max_iterations);
    default: {
      SubpixelResult result;  // not an odd window in 3..15: nothing to refine
      result.position = cur_start;
      return result;
    }
  }
}

}  // namespace

SubpixelResult refine_subpixel(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                               const Eigen::Vector2f& cur_start, int window, float max_shift,
                               int max_iterations) {
  return refine_any<true>(ref, ref_px, cur, cur_start, window, max_shift, max_iterations);
}

SubpixelResult refine_subpixel_scalar(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                                      const Eigen::Vector2f& cur_start, int window, float max_shift,
                                      int max_iterations) {
  return refine_any<false>(ref, ref_px, cur, cur_start, window, max_shift, max_iterations);
}

}  // namespace kestrel::vo
