#pragma once
// One-to-one association of two sorted streams of time stamps (RGB and depth frames of a TUM
// sequence; the same rule as TUM's associate.py, written here).
//
// Rule: every pair (a, b) with |t_a - t_b| <= max_difference_us is a candidate; candidates
// are taken in increasing |t_a - t_b| (ties: lower index a, then lower index b) and accepted
// when neither side is used yet. So each item is used at most once, and a conflict goes to
// the closer pair. Pairs are returned in increasing index a; index b increases with them
// unless max_difference_us exceeds the spacing of a stream (two pairs can only cross when
// one of them spans more than a frame interval: never with TUM's 30 Hz frames and 20 ms).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace kestrel::tum {

struct AssociatedPair {
  size_t a = 0;  ///< index into times_a
  size_t b = 0;  ///< index into times_b
};

struct Association {
  std::vector<AssociatedPair> pairs;  ///< sorted by a
  size_t unmatched_a = 0;             ///< items of a without a partner
  size_t unused_b = 0;                ///< items of b left over
};

/// Both inputs must be sorted in strictly increasing order (throws std::invalid_argument
/// otherwise); max_difference_us must be >= 0.
Association associate(const std::vector<int64_t>& times_a, const std::vector<int64_t>& times_b,
                      int64_t max_difference_us);

}  // namespace kestrel::tum
