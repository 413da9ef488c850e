#pragma once
// 256-bit binary descriptors (ORB) as four 64-bit words: Hamming distance by popcount and the
// bitwise majority that is the "mean" of a cluster of them (k-majority clustering).

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/core.hpp>
#include <vector>

namespace kestrel::slam {

using Descriptor = std::array<uint64_t, 4>;

/// Bits set in `x`. The instruction where the build may use it; the baseline x86-64 build may
/// not (POPCNT came with SSE4.2), and there GCC's builtin is a call to libgcc's __popcountdi2:
/// the same bit-parallel sum as below, but four calls per descriptor pair, which were a third
/// of a SLAM run's time. Inline, the run took a third less.
inline int popcount64(uint64_t x) {
#if defined(__POPCNT__) || !(defined(__x86_64__) || defined(__i386__))
  return __builtin_popcountll(x);
#else
  x = x - ((x >> 1) & 0x5555555555555555ULL);
  x = (x & 0x3333333333333333ULL) + ((x >> 2) & 0x3333333333333333ULL);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
  return static_cast<int>((x * 0x0101010101010101ULL) >> 56);
#endif
}

inline int hamming(const Descriptor& a, const Descriptor& b) {
  return popcount64(a[0] ^ b[0]) + popcount64(a[1] ^ b[1]) + popcount64(a[2] ^ b[2]) + popcount64(a[3] ^ b[3]);
}

/// The descriptor of `train` nearest to `d` by Hamming distance (the lowest index of a tie),
/// its distance, and the second-nearest distance (INT_MAX where there is none).
struct NearestTwo {
  int index = -1;
  int best = std::numeric_limits<int>::max();
  int second = std::numeric_limits<int>::max();
};
/// Brute force over `train`, with the CPU's POPCNT where it has one (chosen at run time: the
/// baseline x86-64 build cannot assume it).
NearestTwo nearest_two(const Descriptor& d, const std::vector<Descriptor>& train);

/// Row `row` of a CV_8UC1 matrix of 32-byte descriptors.
inline Descriptor descriptor_at(const cv::Mat& descriptors, int row) {
  Descriptor d;
  std::memcpy(d.data(), descriptors.ptr<uint8_t>(row), sizeof(Descriptor));
  return d;
}

/// All rows of a CV_8UC1 matrix of 32-byte descriptors (throws std::invalid_argument otherwise).
std::vector<Descriptor> to_descriptors(const cv::Mat& descriptors);

/// Each bit set where more than half of `members` have it set (ties: cleared).
Descriptor majority(const std::vector<Descriptor>& all, const std::vector<int>& members);

}  // namespace kestrel::slam
