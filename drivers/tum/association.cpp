#include "drivers/tum/association.h"

#include <algorithm>
#include <stdexcept>
#include <optional>
#include <string>

namespace kestrel::tum {
namespace {

void require_increasing(const std::vector<int64_t>& times, const char* name) {
  for (size_t i = 1; i < times.size(); ++i) {
    if (times[i] <= times[i - 1]) {
      throw std::invalid_argument(std::string("associate: ") + name + " is not strictly increasing");
    }
  }
}

}  // namespace

Association associate(const std::vector<int64_t>& times_a, const std::vector<int64_t>& times_b,
                      int64_t max_difference_us) {
  if (max_difference_us < 0) throw std::invalid_argument("associate: negative max difference");
  require_increasing(times_a, "times_a");
  require_increasing(times_b, "times_b");

  // Both streams are sorted, so the nearest b of each a is next to where a would go in b,
  // and that place only moves forward: O(n + m).
  Association result;
  std::vector<int> uses(times_b.size(), 0);
  size_t next = 0;  // the first b not before a
  for (size_t a = 0; a < times_a.size(); ++a) {
    while (next < times_b.size() && times_b[next] < times_a[a]) ++next;
    // Written as differences so that no sum can overflow for time stamps near the limits.
    std::optional<size_t> best;
    if (next > 0 && times_a[a] - times_b[next - 1] <= max_difference_us) best = next - 1;
    if (next < times_b.size() && times_b[next] - times_a[a] <= max_difference_us &&
        (!best || times_b[next] - times_a[a] < times_a[a] - times_b[*best]))
      best = next;
    if (!best) {
      ++result.unmatched_a;
      continue;
    }
    result.pairs.push_back({a, *best});
    if (++uses[*best] == 2) ++result.shared_b;
  }
  result.unused_b = static_cast<size_t>(std::count(uses.begin(), uses.end(), 0));
  return result;
}

}  // namespace kestrel::tum
