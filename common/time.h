#pragma once
// Time stamps: int64 microseconds ("utime") everywhere inside kestrel; decimal seconds in
// text files (TUM format). Conversions here are exact: a double would lose the last digits of
// 1305031229.528784.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace kestrel {

/// "1305031229.528784" -> 1305031229528784. Digits beyond microseconds are rounded half up.
/// Empty for anything that is not a plain non-negative decimal number.
std::optional<int64_t> parse_seconds(std::string_view text);

/// 1305031229528784 -> "1305031229.528784" (always six decimals).
std::string format_seconds(int64_t utime);

/// Seconds as double, for arithmetic on differences.
inline double to_seconds(int64_t utime) { return 1e-6 * static_cast<double>(utime); }

}  // namespace kestrel
