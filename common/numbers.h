#pragma once
// The few numeric constants several components need, spelled once (C++17 has no <numbers>).

#include <limits>

namespace kestrel {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;
inline constexpr double kDegree = kPi / 180.0;  ///< one degree in radians
inline constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace kestrel
