#include "vo/dense_depth.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::vo {

namespace {

// The block's reading (its central half, see below) from its count, sum and spread.
inline float block_value(int count, int sum, int lo, int hi, int reads, double max_discontinuity) {
  if (count * 2 < reads) return 0.0f;  // mostly holes
  if (static_cast<double>(hi - lo) > max_discontinuity * lo) return 0.0f;
  return 1e-3f * static_cast<float>(sum) / static_cast<float>(count);
}

#if defined(__SSE2__)
// 8-pixel blocks: the central 4 x 4 readings of each, one 8-pixel load per row.
void block_depths_8_sse2(const cv::Mat& depth_mm, int lo_mm, int hi_mm, double max_discontinuity,
                         int width, int height, std::vector<float>& z) {
  const __m128i lo_m1 = _mm_set1_epi16(static_cast<int16_t>(lo_mm - 1));
  const __m128i hi_p1 = _mm_set1_epi16(static_cast<int16_t>(hi_mm + 1));
  const __m128i centre = _mm_setr_epi16(0, 0, -1, -1, -1, -1, 0, 0);
  const __m128i ones = _mm_set1_epi16(1);
  const __m128i big = _mm_set1_epi16(32767);
  for (int y = 0; y < height; ++y) {
    const uint16_t* rows[4];
    for (int r = 0; r < 4; ++r) rows[r] = depth_mm.ptr<uint16_t>(y * 8 + 2 + r);
    for (int x = 0; x < width; ++x) {
      __m128i sum = _mm_setzero_si128(), count = _mm_setzero_si128();
      __m128i mn = big, mx = _mm_setzero_si128();
      for (int r = 0; r < 4; ++r) {
        const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(rows[r] + 8 * x));
        // Signed compares: readings above 32767 mm are negative here and fail the first.
        const __m128i ok = _mm_and_si128(_mm_and_si128(_mm_cmpgt_epi16(v, lo_m1), _mm_cmplt_epi16(v, hi_p1)), centre);
        const __m128i kept = _mm_and_si128(v, ok);
        sum = _mm_add_epi32(sum, _mm_madd_epi16(kept, ones));
        count = _mm_sub_epi16(count, ok);
        mn = _mm_min_epi16(mn, _mm_or_si128(kept, _mm_andnot_si128(ok, big)));
        mx = _mm_max_epi16(mx, kept);
      }
      sum = _mm_add_epi32(sum, _mm_shuffle_epi32(sum, _MM_SHUFFLE(1, 0, 3, 2)));
      sum = _mm_add_epi32(sum, _mm_shuffle_epi32(sum, _MM_SHUFFLE(2, 3, 0, 1)));
      count = _mm_madd_epi16(count, ones);
      count = _mm_add_epi32(count, _mm_shuffle_epi32(count, _MM_SHUFFLE(1, 0, 3, 2)));
      count = _mm_add_epi32(count, _mm_shuffle_epi32(count, _MM_SHUFFLE(2, 3, 0, 1)));
      mn = _mm_min_epi16(mn, _mm_shuffle_epi32(mn, _MM_SHUFFLE(1, 0, 3, 2)));
      mn = _mm_min_epi16(mn, _mm_shuffle_epi32(mn, _MM_SHUFFLE(2, 3, 0, 1)));
      mn = _mm_min_epi16(mn, _mm_srli_epi32(mn, 16));
      mx = _mm_max_epi16(mx, _mm_shuffle_epi32(mx, _MM_SHUFFLE(1, 0, 3, 2)));
      mx = _mm_max_epi16(mx, _mm_shuffle_epi32(mx, _MM_SHUFFLE(2, 3, 0, 1)));
      mx = _mm_max_epi16(mx, _mm_srli_epi32(mx, 16));
      z[static_cast<size_t>(y * width + x)] =
          block_value(_mm_cvtsi128_si32(count), _mm_cvtsi128_si32(sum), _mm_extract_epi16(mn, 0),
                      _mm_extract_epi16(mx, 0), 16, max_discontinuity);
    }
  }
}
#endif

}  // namespace

void block_depths(const cv::Mat& depth_mm, const DepthOptions& o, int level, bool allow_simd,
                  std::vector<float>& z) {
  const int s = 1 << level;
  const int width = depth_mm.cols / s, height = depth_mm.rows / s;
  z.assign(static_cast<size_t>(width) * static_cast<size_t>(height), 0.0f);
  const int lo_mm = static_cast<int>(std::ceil(1e3 * o.min_m));
  const int hi_mm = static_cast<int>(std::floor(1e3 * o.max_m));
#if defined(__SSE2__)
  if (allow_simd && s == 8 && hi_mm < 32767 && lo_mm >= 1) {
    block_depths_8_sse2(depth_mm, lo_mm, hi_mm, o.max_discontinuity, width, height, z);
    return;
  }
#else
  (void)allow_simd;
#endif
  // The central half of each block side (all of it for blocks of 1 or 2 pixels): its mean is
  // the depth at the block's centre on a plane, at a quarter of the reads.
  const int b0 = s >= 4 ? s / 4 : 0, b1 = s >= 4 ? s - s / 4 : s;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      int count = 0, sum = 0, lo = 1 << 30, hi = 0;
      for (int dy = b0; dy < b1; ++dy) {
        const uint16_t* row = depth_mm.ptr<uint16_t>(y * s + dy) + x * s;
        for (int dx = b0; dx < b1; ++dx) {
          const int d = row[dx];
          if (d < lo_mm || d > hi_mm) continue;
          ++count;
          sum += d;
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
      }
      z[static_cast<size_t>(y * width + x)] =
          block_value(count, sum, lo, hi, (b1 - b0) * (b1 - b0), o.max_discontinuity);
    }
  }
}

void build_dense_depth(const cv::Mat& depth_mm, const sensors::Lens& lens, const DepthOptions& o, int level,
                       DenseDepth& out) {
  const int s = 1 << level;
  out.scale = s;
  out.width = depth_mm.cols / s;
  out.height = depth_mm.rows / s;
  const size_t n = static_cast<size_t>(out.width) * static_cast<size_t>(out.height);
  // The rays through the blocks' centres, kept while the lens and the grid stay the same.
  if (out.rays.size() != n || !lens.prepared_for(out.rays_camera, out.rays_distorted)) {
    out.rays.resize(n);
    const float centre_offset = 0.5f * float(s - 1);
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x)
        out.rays[static_cast<size_t>(y * out.width + x)] =
            lens.ray(float(x * s) + centre_offset, float(y * s) + centre_offset);
    out.rays_camera = lens.camera();
    out.rays_distorted = lens.uses_distortion();
  }
  block_depths(depth_mm, o, level, true, out.depth_scratch);
  out.points.resize(n);
  out.normals.assign(n, Eigen::Vector3f::Zero());
  for (size_t i = 0; i < n; ++i) out.points[i] = out.depth_scratch[i] * out.rays[i];
  for (int y = 1; y + 1 < out.height; ++y) {
    for (int x = 1; x + 1 < out.width; ++x) {
      const size_t i = static_cast<size_t>(y * out.width + x);
      const Eigen::Vector3f& P = out.points[i];
      if (P.z() <= 0.0f) continue;
      const Eigen::Vector3f& l = out.points[i - 1];
      const Eigen::Vector3f& r = out.points[i + 1];
      const Eigen::Vector3f& u = out.points[i - static_cast<size_t>(out.width)];
      const Eigen::Vector3f& d = out.points[i + static_cast<size_t>(out.width)];
      if (l.z() <= 0.0f || r.z() <= 0.0f || u.z() <= 0.0f || d.z() <= 0.0f) continue;
      const float tol = static_cast<float>(o.max_discontinuity) * P.z();
      if (std::abs(l.z() - P.z()) > tol || std::abs(r.z() - P.z()) > tol || std::abs(u.z() - P.z()) > tol ||
          std::abs(d.z() - P.z()) > tol)
        continue;
      Eigen::Vector3f nrm = (r - l).cross(d - u);
      const float len = nrm.norm();
      if (!(len > 0.0f)) continue;
      nrm /= len;
      if (nrm.dot(P) > 0.0f) nrm = -nrm;
      out.normals[i] = nrm;
    }
  }
}

}  // namespace kestrel::vo
