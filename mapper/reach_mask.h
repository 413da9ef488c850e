#pragma once
// Which of four neighbouring pixels have a ray reaching a threshold, as a bit mask: the cell
// search (scan_integrator.cpp) scans a cell's image four pixels (one tile row) at a time and
// looks only at the pixels whose bit is set, instead of testing every pixel's reach in turn.
//
// Bit k is set iff values[k] >= threshold and values[k] > 0 (a reach of 0 means no ray). With
// SSE2 the four compares are one instruction each; reaching4_scalar() is the same answer
// without it (the fallback, and the reference the tests compare against, NaN included).

#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::mapper {

inline unsigned reaching_scalar(const float* values, int count, float threshold) {
  unsigned mask = 0;
  for (int k = 0; k < count; ++k) {
    if (values[k] >= threshold && values[k] > 0.0f) mask |= 1u << k;
  }
  return mask;
}

inline unsigned reaching4_scalar(const float* values, float threshold) {
  return reaching_scalar(values, 4, threshold);
}

/// values[0..3] must be readable.
inline unsigned reaching4(const float* values, float threshold) {
#if defined(__SSE2__)
  const __m128 v = _mm_loadu_ps(values);
  const __m128 ok = _mm_and_ps(_mm_cmpge_ps(v, _mm_set1_ps(threshold)), _mm_cmpgt_ps(v, _mm_setzero_ps()));
  return static_cast<unsigned>(_mm_movemask_ps(ok));
#else
  return reaching4_scalar(values, threshold);
#endif
}

/// Bits k (0..3) for the pixels u0 + k that lie in [lo, hi]; 0 when none do.
inline unsigned pixel_bits(int lo, int hi, int u0) {
  const int a = lo > u0 ? lo - u0 : 0;
  const int b = hi < u0 + 3 ? hi - u0 : 3;
  if (a > b) return 0;
  return ((2u << b) - 1u) & ~((1u << a) - 1u);
}

}  // namespace kestrel::mapper
