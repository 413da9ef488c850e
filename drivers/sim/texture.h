#pragma once
// A tiling colour texture with its mip-map chain, and the trilinear lookup the renderer uses.
//
// Invariants: level 0 is square with a power-of-two side; level l has side (size >> l), down to
// one texel, each texel the mean of the 2x2 texels below it (box pre-filter), so a lookup at the
// level matching the pixel footprint does not alias. Texels are packed R | G << 8 | B << 16.
// Texture coordinates are in level-0 texels and wrap (the texture tiles the plane).
// Each level is stored with one extra column and row (copies of the first ones), so the 2x2
// texels of a bilinear lookup are two adjacent pairs of a row and the next row, wrap or not.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <opencv2/core/mat.hpp>
#include <vector>

namespace kestrel::sim {

class MipTexture {
 public:
  /// From a CV_32FC3 image (R, G, B in [0, 1]) that tiles periodically.
  explicit MipTexture(const cv::Mat& rgb);

  int size() const { return size_; }
  int levels() const { return static_cast<int>(levels_.size()); }
  /// Level `l`'s texels, row-major, (size >> l) squared (without the stored wrap copies).
  std::vector<uint32_t> level(int l) const;
  /// Mean colour (the last level), R, G, B in [0, 1].
  const Eigen::Vector3f& mean() const { return mean_; }

  /// Colour at (x, y) level-0 texels and level of detail `lod` (log2 of the pixel footprint
  /// in level-0 texels, clamped to the chain), packed like the texels. Bilinear within a level;
  /// between levels it blends only when `lod` is within a quarter level of the midpoint
  /// ("brilinear"), which halves the cost of trilinear filtering at no visible loss.
  uint32_t sample(float x, float y, float lod) const {
    const int top = levels() - 1;
    if (lod <= 0.0f) return bilinear(0, x, y);
    if (lod >= static_cast<float>(top)) return bilinear(top, x, y);
    const int l = static_cast<int>(lod);
    const float frac = lod - static_cast<float>(l);
    if (frac < 0.25f) return bilinear(l, x, y);
    if (frac > 0.75f) return bilinear(l + 1, x, y);
    return lerp(bilinear(l, x, y), bilinear(l + 1, x, y), static_cast<uint32_t>((frac - 0.25f) * 512.0f));
  }

  /// Bilinear lookup in level `l` at (x, y) level-0 texels, packed.
  uint32_t bilinear(int l, float x, float y) const {
    const float scale = inverse_scale_[l];
    const float fx = x * scale - 0.5f, fy = y * scale - 0.5f;
    const float x0 = floor_fast(fx), y0 = floor_fast(fy);
    const uint32_t wx = static_cast<uint32_t>((fx - x0) * 256.0f), wy = static_cast<uint32_t>((fy - y0) * 256.0f);
    const uint32_t mask = static_cast<uint32_t>((size_ >> l) - 1);
    const size_t stride = static_cast<size_t>(mask) + 2;
    const uint32_t ix = static_cast<uint32_t>(static_cast<int64_t>(x0)) & mask;
    const uint32_t iy = static_cast<uint32_t>(static_cast<int64_t>(y0)) & mask;
    const uint32_t* d = levels_[l].data() + iy * stride + ix;
    return lerp(lerp(d[0], d[1], wx), lerp(d[stride], d[stride + 1], wx), wy);
  }

  /// Bilinear samples of level `l` along a line: out[i] at (x + i dx, y + i dy), where x, y
  /// are level-l texel coordinates in 16.16 fixed point, half-texel offset already applied.
  /// Unsigned arithmetic wraps at 2^16 texels, a multiple of every level's side, so the
  /// coordinates wrap like the texture. The renderer's inner loop: no float, no branch.
  /// With SSE2, one pixel's four texels are two 64-bit loads widened to 16 bits per channel,
  /// and the same integer lerps as lerp() (bit-identical to the scalar path).
  void bilinear_span(int l, uint32_t x, uint32_t y, int32_t dx, int32_t dy, int n, uint32_t* out) const {
    const uint32_t mask = static_cast<uint32_t>((size_ >> l) - 1);
    const size_t stride = static_cast<size_t>(mask) + 2;
    const uint32_t* d = levels_[l].data();
#if defined(__SSE2__)
    const __m128i zero = _mm_setzero_si128();
    int i = 0;
    {
      // Four pixels per iteration, as two pairs: a pair's texels (ix) in one register of
      // 16-bit lanes, its texels (ix + 1) in another, the weights from the coordinates in
      // 32-bit lanes broadcast to each pixel's four channels.
      const __m128i c256 = _mm_set1_epi16(256), m255 = _mm_set1_epi32(255);
      const uint32_t ux = static_cast<uint32_t>(dx), uy = static_cast<uint32_t>(dy);
      const __m128i steps_x = _mm_set_epi32(static_cast<int>(3u * ux), static_cast<int>(2u * ux), static_cast<int>(ux), 0);
      const __m128i steps_y = _mm_set_epi32(static_cast<int>(3u * uy), static_cast<int>(2u * uy), static_cast<int>(uy), 0);
      auto pair = [&](const uint32_t* a, const uint32_t* b, __m128i wx, __m128i wy, uint32_t* o) {
        const __m128i top = _mm_unpacklo_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a)),
                                               _mm_loadl_epi64(reinterpret_cast<const __m128i*>(b)));
        const __m128i bottom = _mm_unpacklo_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a + stride)),
                                                  _mm_loadl_epi64(reinterpret_cast<const __m128i*>(b + stride)));
        const __m128i iwx = _mm_sub_epi16(c256, wx), iwy = _mm_sub_epi16(c256, wy);
        const __m128i t = _mm_srli_epi16(_mm_add_epi16(_mm_mullo_epi16(_mm_unpacklo_epi8(top, zero), iwx),
                                                       _mm_mullo_epi16(_mm_unpackhi_epi8(top, zero), wx)), 8);
        const __m128i u = _mm_srli_epi16(_mm_add_epi16(_mm_mullo_epi16(_mm_unpacklo_epi8(bottom, zero), iwx),
                                                       _mm_mullo_epi16(_mm_unpackhi_epi8(bottom, zero), wx)), 8);
        const __m128i v = _mm_srli_epi16(_mm_add_epi16(_mm_mullo_epi16(t, iwy), _mm_mullo_epi16(u, wy)), 8);
        _mm_storel_epi64(reinterpret_cast<__m128i*>(o), _mm_packus_epi16(v, zero));
      };
      // [w0 w0 w0 w0 w1 w1 w1 w1] (16-bit) from 32-bit lanes [w0 w1 ...] twice over.
      auto spread = [](__m128i w2) { return _mm_shufflehi_epi16(_mm_shufflelo_epi16(w2, 0), 0); };
      for (; i + 4 <= n; i += 4) {
        const __m128i wx = _mm_and_si128(_mm_srli_epi32(_mm_add_epi32(_mm_set1_epi32(static_cast<int>(x)), steps_x), 8), m255);
        const __m128i wy = _mm_and_si128(_mm_srli_epi32(_mm_add_epi32(_mm_set1_epi32(static_cast<int>(y)), steps_y), 8), m255);
        const uint32_t* p[4];
        for (auto& q : p) {
          q = d + ((y >> 16) & mask) * stride + ((x >> 16) & mask);
          x += ux;
          y += uy;
        }
        pair(p[0], p[1], spread(_mm_unpacklo_epi32(wx, wx)), spread(_mm_unpacklo_epi32(wy, wy)), out + i);
        pair(p[2], p[3], spread(_mm_unpackhi_epi32(wx, wx)), spread(_mm_unpackhi_epi32(wy, wy)), out + i + 2);
      }
    }
    // Per-lane weights: 256 - w in the low four 16-bit lanes, w in the high four.
    const __m128i base = _mm_set_epi16(0, 0, 0, 0, 256, 256, 256, 256);
    const __m128i sign = _mm_set_epi16(1, 1, 1, 1, -1, -1, -1, -1);
    for (; i < n; ++i) {
      const uint32_t ix = (x >> 16) & mask, iy = (y >> 16) & mask;
      const uint32_t* p = d + iy * stride + ix;
      const __m128i top = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
      const __m128i bottom = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + stride));
      const __m128i wx = _mm_add_epi16(base, _mm_mullo_epi16(sign, _mm_set1_epi16(static_cast<short>((x >> 8) & 255u))));
      const __m128i wy = _mm_add_epi16(base, _mm_mullo_epi16(sign, _mm_set1_epi16(static_cast<short>((y >> 8) & 255u))));
      // Products stay below 2^16 (255 * 256), so 16-bit lanes hold them exactly.
      const __m128i t = _mm_mullo_epi16(_mm_unpacklo_epi8(top, zero), wx);     // t00 (256-wx) | t01 wx
      const __m128i b = _mm_mullo_epi16(_mm_unpacklo_epi8(bottom, zero), wx);  // t10 (256-wx) | t11 wx
      const __m128i h = _mm_srli_epi16(_mm_add_epi16(_mm_unpacklo_epi64(t, b), _mm_unpackhi_epi64(t, b)), 8);
      const __m128i v = _mm_mullo_epi16(h, wy);                                // top (256-wy) | bottom wy
      const __m128i sum = _mm_srli_epi16(_mm_add_epi16(v, _mm_srli_si128(v, 8)), 8);
      out[i] = static_cast<uint32_t>(_mm_cvtsi128_si32(_mm_packus_epi16(sum, zero)));
      x += static_cast<uint32_t>(dx);
      y += static_cast<uint32_t>(dy);
    }
#else
    for (int i = 0; i < n; ++i) {
      const uint32_t ix = (x >> 16) & mask, iy = (y >> 16) & mask;
      const uint32_t wx = (x >> 8) & 255u, wy = (y >> 8) & 255u;
      const uint32_t* p = d + iy * stride + ix;
      out[i] = lerp(lerp(p[0], p[1], wx), lerp(p[stride], p[stride + 1], wx), wy);
      x += static_cast<uint32_t>(dx);
      y += static_cast<uint32_t>(dy);
    }
#endif
  }

  /// Keeps an 8-bit copy of the first channel of every level, for grey_span (a grey texture's
  /// lookups then touch a quarter of the memory).
  void add_grey_levels();
  bool has_grey_levels() const { return !grey_levels_.empty(); }

  /// bilinear_span's first channel, from the grey copy (add_grey_levels); the same integer
  /// lerps, so out[i] == bilinear_span's out[i] & 255 exactly.
  void grey_span(int l, uint32_t x, uint32_t y, int32_t dx, int32_t dy, int n, uint32_t* out) const {
    const uint32_t mask = static_cast<uint32_t>((size_ >> l) - 1);
    const size_t stride = static_cast<size_t>(mask) + 2;
    const uint8_t* d = grey_levels_[static_cast<size_t>(l)].data();
    int i = 0;
#if defined(__SSE2__)
    // Eight pixels at a time: each pixel's two texel pairs are two 16-bit loads into 16-bit
    // lanes, the weights come from the coordinates in 32-bit lanes, and the lerps are the
    // scalar ones (products below 2^16).
    const __m128i low = _mm_set1_epi16(255), c256 = _mm_set1_epi16(256), zero = _mm_setzero_si128();
    const __m128i steps_x = _mm_set_epi32(static_cast<int>(3u * static_cast<uint32_t>(dx)), static_cast<int>(2u * static_cast<uint32_t>(dx)), dx, 0);
    const __m128i steps_y = _mm_set_epi32(static_cast<int>(3u * static_cast<uint32_t>(dy)), static_cast<int>(2u * static_cast<uint32_t>(dy)), dy, 0);
    const __m128i four_x = _mm_set1_epi32(static_cast<int>(4u * static_cast<uint32_t>(dx)));
    const __m128i four_y = _mm_set1_epi32(static_cast<int>(4u * static_cast<uint32_t>(dy)));
    for (; i + 8 <= n; i += 8) {
      const __m128i x0 = _mm_add_epi32(_mm_set1_epi32(static_cast<int>(x)), steps_x), x1 = _mm_add_epi32(x0, four_x);
      const __m128i y0 = _mm_add_epi32(_mm_set1_epi32(static_cast<int>(y)), steps_y), y1 = _mm_add_epi32(y0, four_y);
      const __m128i wx = _mm_packs_epi32(_mm_and_si128(_mm_srli_epi32(x0, 8), _mm_set1_epi32(255)),
                                         _mm_and_si128(_mm_srli_epi32(x1, 8), _mm_set1_epi32(255)));
      const __m128i wy = _mm_packs_epi32(_mm_and_si128(_mm_srli_epi32(y0, 8), _mm_set1_epi32(255)),
                                         _mm_and_si128(_mm_srli_epi32(y1, 8), _mm_set1_epi32(255)));
      __m128i t = zero, b = zero;
      grey_lane<0>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<1>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<2>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<3>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<4>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<5>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<6>(d, stride, mask, x, y, dx, dy, t, b);
      grey_lane<7>(d, stride, mask, x, y, dx, dy, t, b);
      const __m128i iwx = _mm_sub_epi16(c256, wx), iwy = _mm_sub_epi16(c256, wy);
      const __m128i top = _mm_srli_epi16(
          _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(t, low), iwx), _mm_mullo_epi16(_mm_srli_epi16(t, 8), wx)), 8);
      const __m128i bottom = _mm_srli_epi16(
          _mm_add_epi16(_mm_mullo_epi16(_mm_and_si128(b, low), iwx), _mm_mullo_epi16(_mm_srli_epi16(b, 8), wx)), 8);
      const __m128i v = _mm_srli_epi16(_mm_add_epi16(_mm_mullo_epi16(top, iwy), _mm_mullo_epi16(bottom, wy)), 8);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_unpacklo_epi16(v, zero));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i + 4), _mm_unpackhi_epi16(v, zero));
    }
#endif
    for (; i < n; ++i) {
      const uint32_t ix = (x >> 16) & mask, iy = (y >> 16) & mask;
      const uint32_t wx = (x >> 8) & 255u, wy = (y >> 8) & 255u;
      const uint8_t* p = d + iy * stride + ix;
      const uint32_t top = (p[0] * (256u - wx) + p[1] * wx) >> 8;
      const uint32_t bottom = (p[stride] * (256u - wx) + p[stride + 1] * wx) >> 8;
      out[i] = (top * (256u - wy) + bottom * wy) >> 8;
      x += static_cast<uint32_t>(dx);
      y += static_cast<uint32_t>(dy);
    }
  }

  /// 16.16 fixed-point level-l coordinate (half-texel offset applied) of level-0 coordinate
  /// `x`, reduced modulo the level's side first so float keeps sub-texel precision.
  uint32_t fixed_coordinate(int l, float x) const {
    const float side = static_cast<float>(size_ >> l);
    float f = x * inverse_scale_[l] - 0.5f;
    f -= side * floor_fast(f * inverse_side_[l]);  // == f / side: a power of two
    return static_cast<uint32_t>(static_cast<int32_t>(f * 65536.0f));
  }
  /// A step of `dx` level-0 texels in level-l 16.16 fixed point, reduced modulo the side
  /// (which changes no sample, and keeps huge steps at coarse levels from overflowing).
  int32_t fixed_step(int l, float dx) const {
    const float side = static_cast<float>(size_ >> l);
    float f = dx * inverse_scale_[l];
    f -= side * floor_fast(f * inverse_side_[l] + 0.5f);
    return static_cast<int32_t>(f * 65536.0f);
  }

  /// The first channel of a grey texture at (x, y), bilinear in the level nearest `lod`.
  float sample_grey(float x, float y, float lod) const {
    const int l = std::clamp(static_cast<int>(lod + 0.5f), 0, levels() - 1);
    return static_cast<float>(bilinear(l, x, y) & 255u);
  }

  /// Per-channel a + (b - a) * w / 256 on packed texels, two channels per multiply.
  static uint32_t lerp(uint32_t a, uint32_t b, uint32_t w) {
    const uint32_t iw = 256u - w;
    const uint32_t rb = (((a & 0x00ff00ffu) * iw + (b & 0x00ff00ffu) * w) >> 8) & 0x00ff00ffu;
    const uint32_t g = (((a & 0x0000ff00u) * iw + (b & 0x0000ff00u) * w) >> 8) & 0x0000ff00u;
    return rb | g;
  }

 private:
#if defined(__SSE2__)
  // One pixel of grey_span's SIMD loop: its texel pairs (ix, ix + 1) of rows iy and iy + 1
  // into 16-bit lane k of t and b; advances (x, y).
  template <int k>
  static void grey_lane(const uint8_t* d, size_t stride, uint32_t mask, uint32_t& x, uint32_t& y, int32_t dx,
                        int32_t dy, __m128i& t, __m128i& b) {
    const uint8_t* p = d + ((y >> 16) & mask) * stride + ((x >> 16) & mask);
    uint16_t top, bottom;
    std::memcpy(&top, p, sizeof top);
    std::memcpy(&bottom, p + stride, sizeof bottom);
    t = _mm_insert_epi16(t, top, k);
    b = _mm_insert_epi16(b, bottom, k);
    x += static_cast<uint32_t>(dx);
    y += static_cast<uint32_t>(dy);
  }
#endif
  static float floor_fast(float v) {
    const float t = static_cast<float>(static_cast<int64_t>(v));
    return t > v ? t - 1.0f : t;
  }

  int size_ = 0;
  int log2_size_ = 0;
  std::vector<std::vector<uint32_t>> levels_;
  std::vector<std::vector<uint8_t>> grey_levels_;  // same layout, first channel only
  std::vector<float> inverse_scale_;
  std::vector<float> inverse_side_;  // 1 / (size >> l), exact
  Eigen::Vector3f mean_ = Eigen::Vector3f::Zero();
};

}  // namespace kestrel::sim
