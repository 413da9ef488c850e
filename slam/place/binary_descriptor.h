#pragma once
// 256-bit binary descriptors (ORB) as four 64-bit words: Hamming distance by popcount and the
// bitwise majority that is the "mean" of a cluster of them (k-majority clustering).

#include <array>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>
#include <vector>

namespace kestrel::slam {

using Descriptor = std::array<uint64_t, 4>;

inline int hamming(const Descriptor& a, const Descriptor& b) {
  return __builtin_popcountll(a[0] ^ b[0]) + __builtin_popcountll(a[1] ^ b[1]) +
         __builtin_popcountll(a[2] ^ b[2]) + __builtin_popcountll(a[3] ^ b[3]);
}

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
