#pragma once
// The few numeric constants and one-line helpers several components need, spelled once (C++17
// has no <numbers>). One home also keeps them out of the files' anonymous namespaces, where
// two copies in one unity batch (CMakeLists.txt) would be a redefinition.

#include <cmath>
#include <limits>

namespace kestrel {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kDegree = kPi / 180.0;  ///< one degree in radians
inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// v * v: a variance from a standard deviation, without writing the expression twice.
constexpr double sq(double v) { return v * v; }

/// An angle wrapped to (-pi, pi] (headings, yaw differences: the short way round).
inline double wrap_angle(double a) {
  a = std::remainder(a, kTwoPi);
  return a <= -kPi ? a + kTwoPi : a;
}

/// An axis's grid step: 1, 2 or 5 times a power of ten giving about `count` steps over `span` (> 0).
inline double nice_step(double span, int count) {
  const double rough = span / count;
  const double decade = std::pow(10.0, std::floor(std::log10(rough)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * decade >= rough) return m * decade;
  return 10.0 * decade;
}

}  // namespace kestrel
