#include "drivers/tum/association.h"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace kestrel::tum {
namespace {

void require_increasing(const std::vector<int64_t>& times, const char* name) {
  for (size_t i = 1; i < times.size(); ++i) {
    if (times[i] <= times[i - 1]) {
      throw std::invalid_argument(std::string("associate: ") + name + " is not strictly increasing");
    }
  }
}

struct Candidate {
  int64_t difference;
  size_t a;
  size_t b;
};

}  // namespace

Association associate(const std::vector<int64_t>& times_a, const std::vector<int64_t>& times_b,
                      int64_t max_difference_us) {
  if (max_difference_us < 0) throw std::invalid_argument("associate: negative max difference");
  require_increasing(times_a, "times_a");
  require_increasing(times_b, "times_b");

  // Both streams are sorted, so the candidates of each a lie in one window of b that slides
  // forward: O(n + candidates) to collect instead of all n*m pairs.
  std::vector<Candidate> candidates;
  size_t window_begin = 0;
  for (size_t a = 0; a < times_a.size(); ++a) {
    // Written as differences so that no sum can overflow for time stamps near the limits.
    while (window_begin < times_b.size() && times_a[a] - times_b[window_begin] > max_difference_us)
      ++window_begin;
    for (size_t b = window_begin;
         b < times_b.size() && times_b[b] - times_a[a] <= max_difference_us; ++b) {
      const int64_t d = times_b[b] > times_a[a] ? times_b[b] - times_a[a] : times_a[a] - times_b[b];
      candidates.push_back({d, a, b});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.difference, x.a, x.b) < std::tie(y.difference, y.a, y.b);
  });

  std::vector<bool> used_a(times_a.size(), false);
  std::vector<bool> used_b(times_b.size(), false);
  Association result;
  for (const Candidate& c : candidates) {
    if (used_a[c.a] || used_b[c.b]) continue;
    used_a[c.a] = used_b[c.b] = true;
    result.pairs.push_back({c.a, c.b});
  }
  std::sort(result.pairs.begin(), result.pairs.end(),
            [](const AssociatedPair& x, const AssociatedPair& y) { return x.a < y.a; });
  result.unmatched_a = times_a.size() - result.pairs.size();
  result.unused_b = times_b.size() - result.pairs.size();
  return result;
}

}  // namespace kestrel::tum
