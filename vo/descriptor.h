#pragma once
// Patch descriptors: the w x w grey patch around a feature on its pyramid level, normalised by
// subtracting its mean (value - mean + 128, saturated to 0..255), compared by the sum of
// absolute differences (SAD). For w = 9 the bottom-right pixel is dropped to make 80 bytes, a
// multiple of the 16-byte SIMD width (fovis); in general a patch of n pixels keeps
// n - 1 pixels when that is a multiple of 16, and is zero-padded to the next multiple of 16
// otherwise (the padding adds nothing to a SAD).
//
// Invariant: descriptors are stored back to back, bytes() apart, so that a SAD runs on
// whole 16-byte blocks (SSE2 `psadbw` where available, a scalar loop otherwise).

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace kestrel::vo {

/// Bytes of a descriptor of a w x w patch.
int descriptor_bytes(int window_size);

class DescriptorSet {
 public:
  /// Empties the set and sets the patch size (odd, 3..15).
  void reset(int window_size);
  /// Appends the descriptor of the patch centred on (x, y) of `image`; the patch must lie inside.
  void add(const cv::Mat& image, int x, int y);

  int size() const { return count_; }
  int bytes() const { return bytes_; }
  int window_size() const { return window_; }
  const uint8_t* operator[](int i) const {
    return data_.data() + static_cast<size_t>(i) * static_cast<size_t>(bytes_);
  }

 private:
  int window_ = 9;
  int bytes_ = 80;
  int count_ = 0;
  std::vector<uint8_t> data_;
};

/// Sum of absolute differences of two descriptors of `bytes` bytes (a multiple of 16).
int sad(const uint8_t* a, const uint8_t* b, int bytes);
/// The same with the scalar code only (for tests and non-SSE2 targets).
int sad_scalar(const uint8_t* a, const uint8_t* b, int bytes);

}  // namespace kestrel::vo
