#include "vo/image_pyramid.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::vo {
namespace {

// Every filter here is separable with integer weights summing to 64 (or 16 for the pyramid's
// 1-4-6-4-1): the first pass keeps two fractional bits in uint16, the second pass then fits in
// uint16 as well (255 * 64 / 16 * 64 = 65280). Plain loops over contiguous uint16 rows, which
// GCC and Clang vectorise for SSE2 and NEON alike; one thread, no allocation once the buffers
// have their size.
constexpr int kMaxRadius = 3;

// Reflect-101 index (OpenCV's default border): -1 -> 1, n -> n - 2.
inline int reflect101(int i, int n) {
  if (n == 1) return 0;
  while (i < 0 || i >= n) i = i < 0 ? -i : 2 * (n - 1) - i;
  return i;
}

}  // namespace

// R,G,B -> grey with the BT.601 weights in 1/256 (the rounding differs from OpenCV's 14-bit
// weights by at most one grey level).
void rgb_to_grey_scalar(const cv::Mat& rgb, cv::Mat& grey) {
  grey.create(rgb.size(), CV_8UC1);
  const int w = rgb.cols;  // a local, so that the compiler knows the trip count
  for (int y = 0; y < rgb.rows; ++y) {
    const uint8_t* in = rgb.ptr<uint8_t>(y);
    uint8_t* out = grey.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      // 16-bit arithmetic (at most 255 * 256 + 128), which lets the loop vectorise (NEON has
      // de-interleaving loads; SSE2 has none, hence rgb_to_grey's own path there).
      const uint16_t v = static_cast<uint16_t>(77 * in[3 * x] + 150 * in[3 * x + 1] + 29 * in[3 * x + 2] + 128);
      out[x] = static_cast<uint8_t>(v >> 8);
    }
  }
}

void rgb_to_grey(const cv::Mat& rgb, cv::Mat& grey) {
#if defined(__SSE2__)
  grey.create(rgb.size(), CV_8UC1);
  const int w = rgb.cols;
  const __m128i zero = _mm_setzero_si128();
  const __m128i wr = _mm_set1_epi16(77), wg = _mm_set1_epi16(150), wb = _mm_set1_epi16(29);
  const __m128i half = _mm_set1_epi16(128);
  // grey of 8 pixels from their R, G, B widened to 16 bits: the scalar formula exactly (the
  // sum <= 65408 fits an unsigned 16-bit lane; mullo's low halves are the true products).
  auto grey8 = [&](__m128i r, __m128i g, __m128i b) {
    const __m128i s = _mm_add_epi16(_mm_add_epi16(_mm_mullo_epi16(r, wr), _mm_mullo_epi16(g, wg)),
                                    _mm_add_epi16(_mm_mullo_epi16(b, wb), half));
    return _mm_srli_epi16(s, 8);
  };
  for (int y = 0; y < rgb.rows; ++y) {
    const uint8_t* in = rgb.ptr<uint8_t>(y);
    uint8_t* out = grey.ptr<uint8_t>(y);
    int x = 0;
    for (; x + 32 <= w; x += 32) {
      // 32 pixels = 96 bytes in six registers. Interleaving the first 48 bytes with the last
      // 48 (unpack lo/hi of registers k and k + 3) moves byte i to 2i mod 95; five rounds
      // move it to 32 i mod 95, which for i = 3 p + c is 32 c + p: R in registers 0-1, G in
      // 2-3, B in 4-5, each in pixel order.
      __m128i a[6];
      for (int k = 0; k < 6; ++k) a[k] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 3 * x + 16 * k));
      for (int round = 0; round < 5; ++round) {
        __m128i b[6];
        for (int k = 0; k < 3; ++k) {
          b[2 * k] = _mm_unpacklo_epi8(a[k], a[k + 3]);
          b[2 * k + 1] = _mm_unpackhi_epi8(a[k], a[k + 3]);
        }
        for (int k = 0; k < 6; ++k) a[k] = b[k];
      }
      const __m128i lo = grey8(_mm_unpacklo_epi8(a[0], zero), _mm_unpacklo_epi8(a[2], zero),
                               _mm_unpacklo_epi8(a[4], zero));
      const __m128i hi = grey8(_mm_unpackhi_epi8(a[0], zero), _mm_unpackhi_epi8(a[2], zero),
                               _mm_unpackhi_epi8(a[4], zero));
      const __m128i lo2 = grey8(_mm_unpacklo_epi8(a[1], zero), _mm_unpacklo_epi8(a[3], zero),
                                _mm_unpacklo_epi8(a[5], zero));
      const __m128i hi2 = grey8(_mm_unpackhi_epi8(a[1], zero), _mm_unpackhi_epi8(a[3], zero),
                                _mm_unpackhi_epi8(a[5], zero));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm_packus_epi16(lo, hi));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x + 16), _mm_packus_epi16(lo2, hi2));
    }
    for (; x < w; ++x) {
      const uint16_t v = static_cast<uint16_t>(77 * in[3 * x] + 150 * in[3 * x + 1] + 29 * in[3 * x + 2] + 128);
      out[x] = static_cast<uint8_t>(v >> 8);
    }
  }
#else
  rgb_to_grey_scalar(rgb, grey);
#endif
}

namespace {

// The separable blur for a kernel of radius R known at compile time, so that the inner loops
// are fixed-length sums the compiler turns into 16-bit vector multiply-adds.
template <int R>
void blur_rows(const cv::Mat& grey, const int* kernel, cv::Mat& out, std::vector<uint16_t>& padded_row,
               std::vector<uint16_t>& column) {
  const int w = grey.cols, h = grey.rows;
  uint16_t k[2 * R + 1];
  for (int i = 0; i <= 2 * R; ++i) k[i] = static_cast<uint16_t>(kernel[i]);
  padded_row.resize(static_cast<size_t>(w + 2 * R));
  column.resize(static_cast<size_t>(w) * static_cast<size_t>(h));
  // Horizontal pass into `column` (two fractional bits), through a row padded by reflection.
  for (int y = 0; y < h; ++y) {
    const uint8_t* in = grey.ptr<uint8_t>(y);
    uint16_t* p = padded_row.data();
    for (int x = 0; x < w; ++x) p[x + R] = in[x];
    for (int x = 1; x <= R; ++x) {
      p[R - x] = in[reflect101(-x, w)];
      p[w - 1 + R + x] = in[reflect101(w - 1 + x, w)];
    }
    uint16_t* o = column.data() + static_cast<size_t>(y) * static_cast<size_t>(w);
    for (int x = 0; x < w; ++x) {
      // The kernel is symmetric: mirrored taps share a multiplication (the same integer sum).
      uint16_t s = static_cast<uint16_t>(8 + k[R] * p[x + R]);  // 8: rounding of the >> 4
      for (int i = 0; i < R; ++i) s = static_cast<uint16_t>(s + k[i] * (p[x + i] + p[x + 2 * R - i]));
      o[x] = static_cast<uint16_t>(s >> 4);
    }
  }
  // Vertical pass: 64 * 1020 + 128 < 65536, so the sums stay in 16 bits.
  for (int y = 0; y < h; ++y) {
    const uint16_t* rows[2 * R + 1];
    for (int i = -R; i <= R; ++i)
      rows[i + R] = column.data() + static_cast<size_t>(reflect101(y + i, h)) * static_cast<size_t>(w);
    uint8_t* o = out.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x) {
      uint16_t s = static_cast<uint16_t>(128 + k[R] * rows[R][x]);
      for (int i = 0; i < R; ++i) s = static_cast<uint16_t>(s + k[i] * (rows[i][x] + rows[2 * R - i][x]));
      o[x] = static_cast<uint8_t>(s >> 8);
    }
  }
}

}  // namespace

void gaussian_kernel_64(double sigma, std::vector<int>& weights) {
  const int r = std::max(1, static_cast<int>(std::ceil(2.0 * sigma)));
  std::vector<double> g(static_cast<size_t>(2 * r + 1));
  double sum = 0.0;
  for (int i = -r; i <= r; ++i) sum += g[static_cast<size_t>(i + r)] = std::exp(-0.5 * i * i / (sigma * sigma));
  weights.assign(g.size(), 0);
  int total = 0;
  for (size_t i = 0; i < g.size(); ++i) total += weights[i] = static_cast<int>(std::lround(64.0 * g[i] / sum));
  weights[static_cast<size_t>(r)] += 64 - total;  // the rounding's remainder goes to the centre
}

void ImagePyramid::blur(const cv::Mat& grey, double sigma, cv::Mat& out) {
  if (kernel_sigma_ != sigma) {
    gaussian_kernel_64(sigma, kernel_);
    kernel_sigma_ = sigma;
  }
  const int r = static_cast<int>(kernel_.size() / 2);
  if (r > kMaxRadius || grey.cols <= r || grey.rows <= r) {
    // Wide kernels are not kestrel's default; OpenCV's exact blur serves them.
    const int k = 2 * static_cast<int>(std::ceil(2.0 * sigma)) + 1;
    cv::GaussianBlur(grey, out, cv::Size(k, k), sigma, sigma, cv::BORDER_REFLECT_101);
    return;
  }
  out.create(grey.size(), CV_8UC1);
  for (int i = 0; i < r; ++i)  // gaussian_kernel_64 makes symmetric kernels; blur_rows relies on it
    if (kernel_[static_cast<size_t>(i)] != kernel_[static_cast<size_t>(2 * r - i)])
      throw std::logic_error("ImagePyramid: asymmetric blur kernel");
  if (r == 1) blur_rows<1>(grey, kernel_.data(), out, row_, column_);
  if (r == 2) blur_rows<2>(grey, kernel_.data(), out, row_, column_);
  if (r == 3) blur_rows<3>(grey, kernel_.data(), out, row_, column_);
}

namespace {

// One row of the halving: the vertical 1-4-6-4-1 into v[0 .. w - 1] (with v[-2], v[-1], v[w],
// v[w + 1] reflected), then the horizontal one at every other column. From column `from` on
// the horizontal pass is scalar (all of it in the reference).
void half_row(const uint8_t* const r[5], int w, uint16_t* v, uint8_t* o, int from) {
  for (int x = 0; x < w; ++x)
    v[x] = static_cast<uint16_t>(r[0][x] + r[4][x] + 4 * (r[1][x] + r[3][x]) + 6 * r[2][x]);
  v[-2] = v[reflect101(-2, w)];
  v[-1] = v[reflect101(-1, w)];
  v[w] = v[reflect101(w, w)];
  v[w + 1] = v[reflect101(w + 1, w)];
  const int ow = (w + 1) / 2;
  for (int x = from; x < ow; ++x) {
    const int c = 2 * x;
    const unsigned s = v[c - 2] + v[c + 2] + 4u * (v[c - 1] + v[c + 1]) + 6u * v[c];
    o[x] = static_cast<uint8_t>((s + 128u) >> 8);
  }
}

void half_size_impl(const cv::Mat& in, cv::Mat& out, std::vector<uint16_t>& row, bool simd) {
  // 1-4-6-4-1 in both directions, then every other pixel (what cv::pyrDown computes).
  const int w = in.cols, h = in.rows;
  const int ow = (w + 1) / 2, oh = (h + 1) / 2;
  out.create(oh, ow, CV_8UC1);
  row.resize(static_cast<size_t>(w + 4));
  uint16_t* v = row.data() + 2;  // v[-2 .. w + 1]
  // Blocks of 8 outputs x0 .. x0 + 7 read v up to 2 x0 + 17 <= w + 1.
  const int blocks = simd && w >= 16 ? (w - 16) / 16 + 1 : 0;
  for (int y = 0; y < oh; ++y) {
    const uint8_t* r[5];
    for (int i = 0; i < 5; ++i) r[i] = in.ptr<uint8_t>(reflect101(2 * y - 2 + i, h));
    uint8_t* o = out.ptr<uint8_t>(y);
#if defined(__SSE2__)
    half_row(r, w, v, o, 8 * blocks);
    // The same sums in 16-bit lanes (at most 16 * 4080 + 128 = 65408): E(j) = v[2j] and
    // O(j) = v[2j + 1] taken apart by packing the low / high halves of 32-bit lanes, then
    // o[x] = (E(x - 1) + E(x + 1) + 4 (O(x - 1) + O(x)) + 6 E(x) + 128) >> 8.
    const __m128i low = _mm_set1_epi32(0xFFFF), half = _mm_set1_epi16(128);
    auto at = [&](int i) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(v + i)); };
    auto evens = [&](__m128i a, __m128i b) { return _mm_packs_epi32(_mm_and_si128(a, low), _mm_and_si128(b, low)); };
    auto odds = [&](__m128i a, __m128i b) { return _mm_packs_epi32(_mm_srli_epi32(a, 16), _mm_srli_epi32(b, 16)); };
    for (int k = 0; k < blocks; ++k) {
      const int c = 16 * k;  // 2 x0
      const __m128i m0 = at(c - 2), m1 = at(c + 6), z0 = at(c), z1 = at(c + 8), p0 = at(c + 2), p1 = at(c + 10);
      const __m128i em = evens(m0, m1), om = odds(m0, m1), e0 = evens(z0, z1), o0 = odds(z0, z1), ep = evens(p0, p1);
      const __m128i six_e0 = _mm_add_epi16(_mm_slli_epi16(e0, 2), _mm_slli_epi16(e0, 1));
      __m128i sum = _mm_add_epi16(_mm_add_epi16(em, ep), _mm_slli_epi16(_mm_add_epi16(om, o0), 2));
      sum = _mm_add_epi16(_mm_add_epi16(sum, six_e0), half);
      const __m128i bytes = _mm_packus_epi16(_mm_srli_epi16(sum, 8), _mm_setzero_si128());
      _mm_storel_epi64(reinterpret_cast<__m128i*>(o + 8 * k), bytes);
    }
#else
    (void)blocks;
    half_row(r, w, v, o, 0);
#endif
  }
}

}  // namespace

void half_size(const cv::Mat& in, cv::Mat& out, std::vector<uint16_t>& row) {
  half_size_impl(in, out, row, true);
}

void half_size_scalar(const cv::Mat& in, cv::Mat& out, std::vector<uint16_t>& row) {
  half_size_impl(in, out, row, false);
}

void ImagePyramid::build(const cv::Mat& image, int levels, double blur_sigma) {
  if (levels < 1) throw std::invalid_argument("ImagePyramid: levels must be >= 1");
  levels_.resize(static_cast<size_t>(levels));
  const cv::Mat* grey = &image;
  if (image.type() == CV_8UC3) {
    rgb_to_grey(image, grey_);
    grey = &grey_;
  } else if (image.type() != CV_8UC1) {
    throw std::invalid_argument("ImagePyramid: image must be CV_8UC3 or CV_8UC1");
  }
  if (blur_sigma > 0.0) {
    blur(*grey, blur_sigma, levels_[0]);
  } else {
    grey->copyTo(levels_[0]);
  }
  for (size_t i = 1; i < levels_.size(); ++i) half_size(levels_[i - 1], levels_[i], row_);
}

void ImagePyramid::swap(ImagePyramid& other) noexcept {
  cv::swap(grey_, other.grey_);
  levels_.swap(other.levels_);
  kernel_.swap(other.kernel_);
  std::swap(kernel_sigma_, other.kernel_sigma_);
  row_.swap(other.row_);
  column_.swap(other.column_);
}

}  // namespace kestrel::vo
