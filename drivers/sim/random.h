#pragma once
// Deterministic random numbers for the synthetic world.
//
// Everything random in the simulator (textures, sensor noise, flights) is drawn from these
// generators, each keyed by the user's seed and a purpose tag (derive()). A fixed seed therefore
// gives identical output on every run, and one part taking more or fewer numbers never shifts
// the draws of another. Nothing here depends on the standard library's distributions, whose
// output is implementation-defined.

#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>

namespace kestrel::sim {

/// SplitMix64 output function: a bijective 64-bit mix with full avalanche.
constexpr uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// A 64-bit tag from a name (FNV-1a), for derive(seed, tag("imu")).
constexpr uint64_t tag(std::string_view name) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : name) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL;
  return h;
}

/// The key of an independent stream below `key`, e.g. derive(seed, tag("imu")).
constexpr uint64_t derive(uint64_t key, uint64_t sub) { return mix64(key ^ mix64(sub)); }

/// A fast 32-bit integer hash with good avalanche, for per-pixel noise: one call per pixel
/// keyed by (frame key, pixel index) keeps the noise independent of evaluation order.
constexpr uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

/// A SplitMix64 stream with uniform and normal draws.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  uint64_t next() { return mix64(state_++); }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [0, n), n > 0.
  int below(int n) { return static_cast<int>(uniform() * n); }
  /// Standard normal (Box-Muller; both values of a pair are used).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = uniform();
    while (u <= 0.0) u = uniform();
    const double r = std::sqrt(-2.0 * std::log(u));
    const double a = 6.283185307179586 * uniform();
    spare_ = r * std::sin(a);
    has_spare_ = true;
    return r * std::cos(a);
  }

 private:
  uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// Standard normal values at the centres of 1024 equal-probability bins, rescaled to unit
/// variance: table[hash & 1023] is a normal draw from 10 random bits, for per-pixel noise.
class NormalTable {
 public:
  static constexpr int kBits = 10;
  static constexpr uint32_t kMask = (1u << kBits) - 1;
  NormalTable();
  float operator[](uint32_t bits) const { return values_[bits & kMask]; }

 private:
  std::array<float, 1u << kBits> values_{};
};

/// The shared table (built once, thread-safe).
const NormalTable& normal_table();

}  // namespace kestrel::sim
