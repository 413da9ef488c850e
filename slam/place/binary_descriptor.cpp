#include "slam/place/binary_descriptor.h"

#include <stdexcept>

namespace kestrel::slam {

namespace {

// The loop of nearest_two, inlined into each kernel below so that its popcounts are compiled
// for that kernel's target.
template <bool kHardwarePopcount>
[[gnu::always_inline]] inline NearestTwo nearest_two_loop(const Descriptor& d, const std::vector<Descriptor>& train) {
  NearestTwo n;
  for (size_t i = 0; i < train.size(); ++i) {
    const Descriptor& t = train[i];
    int h;
    if constexpr (kHardwarePopcount) {
      h = __builtin_popcountll(d[0] ^ t[0]) + __builtin_popcountll(d[1] ^ t[1]) +
          __builtin_popcountll(d[2] ^ t[2]) + __builtin_popcountll(d[3] ^ t[3]);
    } else {
      h = hamming(d, t);
    }
    if (h < n.best) {
      n.second = n.best;
      n.best = h;
      n.index = static_cast<int>(i);
    } else if (h < n.second) {
      n.second = h;
    }
  }
  return n;
}

#if (defined(__x86_64__) || defined(__i386__)) && !defined(__POPCNT__)
[[gnu::target("popcnt")]] NearestTwo nearest_two_popcnt(const Descriptor& d, const std::vector<Descriptor>& train) {
  return nearest_two_loop<true>(d, train);
}
bool cpu_has_popcnt() {
  static const bool has = [] {
    __builtin_cpu_init();  // in case this runs before the CPU model's own constructor
    return __builtin_cpu_supports("popcnt") != 0;
  }();
  return has;
}
#endif

}  // namespace

NearestTwo nearest_two(const Descriptor& d, const std::vector<Descriptor>& train) {
#if (defined(__x86_64__) || defined(__i386__)) && !defined(__POPCNT__)
  if (cpu_has_popcnt()) return nearest_two_popcnt(d, train);
  return nearest_two_loop<false>(d, train);
#else
  return nearest_two_loop<true>(d, train);  // the instruction, or the target's best builtin
#endif
}

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
