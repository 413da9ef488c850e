#pragma once
// Association of two sorted streams of time stamps: each RGB frame of a TUM sequence with a
// depth frame.
//
// Rule: every item of a takes the nearest item of b within max_difference_us (ties: the
// earlier b); an item of b may serve several items of a (counted in shared_b). So every
// colour frame that has a depth frame within the tolerance is kept. TUM's associate.py is
// stricter: it pairs one-to-one, closest pairs first, and drops a colour frame whose nearest
// depth frame went to a neighbour (1 of fr1_xyz's 190 frames, 40 of 613 on a held-out
// sequence: each a frame without an estimate). Such a frame's depth is at most
// max_difference_us from it, as any other's; the VO reads each frame's depth at the depth's
// own time (depth_utime), so a shared depth frame is no different from another.
// Pairs are returned in increasing index a, index b non-decreasing.

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
  size_t unmatched_a = 0;             ///< items of a with no b within the tolerance
  size_t unused_b = 0;                ///< items of b nearest to no item of a
  size_t shared_b = 0;                ///< items of b serving more than one item of a
};

/// Both inputs must be sorted in strictly increasing order (throws std::invalid_argument
/// otherwise); max_difference_us must be >= 0.
Association associate(const std::vector<int64_t>& times_a, const std::vector<int64_t>& times_b,
                      int64_t max_difference_us);

}  // namespace kestrel::tum
