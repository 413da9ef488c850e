#include "vo/descriptor.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
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
  // The patch row by row (the last one cut at n pixels), then its sum and the normalisation
  // as plain loops over the bytes, which vectorise; the padding stays zero.
  for (int dy = -r, k = 0; k < n; ++dy, k += window_)
    std::memcpy(out + k, image.ptr<uint8_t>(y + dy) + (x - r), static_cast<size_t>(std::min(window_, n - k)));
  int sum = 0;
  for (int i = 0; i < n; ++i) sum += out[i];
  const int mean = (sum + n / 2) / n;
  int i = 0;
#if defined(__SSE2__)
  // clamp(v - mean + 128, 0, 255) as one saturating byte addition or subtraction.
  const int shift = 128 - mean;  // -127 .. 128
  const __m128i delta = _mm_set1_epi8(static_cast<char>(static_cast<uint8_t>(std::abs(shift))));
  for (; i + 16 <= n; i += 16) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(out + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i),
                     shift >= 0 ? _mm_adds_epu8(v, delta) : _mm_subs_epu8(v, delta));
  }
#endif
  for (; i < n; ++i) out[i] = static_cast<uint8_t>(std::clamp(out[i] - mean + 128, 0, 255));
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
