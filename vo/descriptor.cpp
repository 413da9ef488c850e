#include "vo/descriptor.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace kestrel::vo {

int descriptor_bytes(int window_size) {
  const int n = window_size * window_size;
  if (n % 16 == 1) return n - 1;
  return (n + 15) / 16 * 16;
}

void DescriptorSet::reset(int window_size) {
  if (window_size < 3 || window_size > 15 || window_size % 2 == 0)
    throw std::invalid_argument("DescriptorSet: window size must be odd, 3..15");
  window_ = window_size;
  bytes_ = descriptor_bytes(window_size);
  count_ = 0;
  data_.clear();
}

void DescriptorSet::add(const cv::Mat& image, int x, int y) {
  const int r = window_ / 2;
  const size_t at = data_.size();
  data_.resize(at + static_cast<size_t>(bytes_), 0);
  uint8_t* out = data_.data() + at;
  const int n = std::min(window_ * window_, bytes_);  // pixels kept
  int sum = 0;
  int k = 0;
  for (int dy = -r; dy <= r && k < n; ++dy) {
    const uint8_t* row = image.ptr<uint8_t>(y + dy) + x;
    for (int dx = -r; dx <= r && k < n; ++dx, ++k) {
      out[k] = row[dx];
      sum += row[dx];
    }
  }
  const int mean = (sum + n / 2) / n;
  for (int i = 0; i < n; ++i) out[i] = static_cast<uint8_t>(std::clamp(out[i] - mean + 128, 0, 255));
  ++count_;
}

int sad_scalar(const uint8_t* a, const uint8_t* b, int bytes) {
  int s = 0;
  for (int i = 0; i < bytes; ++i) s += std::abs(int(a[i]) - int(b[i]));
  return s;
}

int sad(const uint8_t* a, const uint8_t* b, int bytes) {
#if defined(__SSE2__)
  __m128i acc = _mm_setzero_si128();
  for (int i = 0; i < bytes; i += 16) {
    const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(a + i));
    const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i));
    acc = _mm_add_epi64(acc, _mm_sad_epu8(va, vb));
  }
  return _mm_cvtsi128_si32(acc) + _mm_cvtsi128_si32(_mm_unpackhi_epi64(acc, acc));
#else
  return sad_scalar(a, b, bytes);
#endif
}

}  // namespace kestrel::vo
