#include "slam/place/binary_descriptor.h"

#include <stdexcept>

namespace kestrel::slam {

std::vector<Descriptor> to_descriptors(const cv::Mat& descriptors) {
  if (descriptors.empty()) return {};
  if (descriptors.type() != CV_8UC1 || descriptors.cols != static_cast<int>(sizeof(Descriptor))) {
    throw std::invalid_argument("descriptors must be CV_8UC1 rows of 32 bytes (ORB)");
  }
  std::vector<Descriptor> out(static_cast<size_t>(descriptors.rows));
  for (int r = 0; r < descriptors.rows; ++r) out[r] = descriptor_at(descriptors, r);
  return out;
}

Descriptor majority(const std::vector<Descriptor>& all, const std::vector<int>& members) {
  int counts[256] = {0};
  for (const int m : members) {
    const Descriptor& d = all[m];
    for (int w = 0; w < 4; ++w) {
      uint64_t bits = d[w];
      while (bits) {
        counts[w * 64 + __builtin_ctzll(bits)]++;
        bits &= bits - 1;
      }
    }
  }
  Descriptor out{};
  const size_t half = members.size() / 2;
  for (int b = 0; b < 256; ++b) {
    if (static_cast<size_t>(counts[b]) > half) out[b / 64] |= uint64_t{1} << (b % 64);
  }
  return out;
}

}  // namespace kestrel::slam
