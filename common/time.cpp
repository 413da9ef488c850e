#include "common/time.h"

#include <cinttypes>
#include <cstdio>
#include <limits>

namespace kestrel {

std::optional<int64_t> parse_seconds(std::string_view text) {
  if (text.empty()) return std::nullopt;
  int64_t whole = 0;
  size_t i = 0;
  constexpr int64_t kMaxWhole = std::numeric_limits<int64_t>::max() / 1000000 - 1;
  for (; i < text.size() && text[i] != '.'; ++i) {
    if (text[i] < '0' || text[i] > '9') return std::nullopt;
    whole = whole * 10 + (text[i] - '0');
    if (whole > kMaxWhole) return std::nullopt;
  }
  if (i == 0) return std::nullopt;  // ".5" is not accepted: TUM files always have digits
  int64_t frac = 0;
  int digits = 0;
  bool round_up = false;
  if (i < text.size()) {
    ++i;  // '.'
    if (i == text.size()) return std::nullopt;
    for (; i < text.size(); ++i) {
      const char c = text[i];
      if (c < '0' || c > '9') return std::nullopt;
      if (digits < 6) {
        frac = frac * 10 + (c - '0');
        ++digits;
      } else if (digits == 6) {
        round_up = c >= '5';
        ++digits;
      }
    }
  }
  for (int d = std::min(digits, 6); d < 6; ++d) frac *= 10;
  return whole * 1000000 + frac + (round_up ? 1 : 0);
}

std::string format_seconds(int64_t utime) {
  char buf[32];
  const char* sign = utime < 0 ? "-" : "";
  const uint64_t a = utime < 0 ? static_cast<uint64_t>(-(utime + 1)) + 1 : static_cast<uint64_t>(utime);
  std::snprintf(buf, sizeof buf, "%s%" PRIu64 ".%06" PRIu64, sign, a / 1000000, a % 1000000);
  return buf;
}

}  // namespace kestrel
