#pragma once
// An inverted index over bag-of-words vectors: for a query, the stored entries sharing words
// with it, scored by bow_score, best first — the cost grows with the shared words, not with
// the number of entries.
//
// Invariant: entries are numbered 0, 1, ... in the order they were added.

#include <functional>
#include <vector>

#include "slam/place/vocabulary.h"

namespace kestrel::slam {

struct BowMatch {
  int entry = -1;
  double score = 0.0;
};

class BowDatabase {
 public:
  /// Adds a vector; returns its entry number.
  int add(const BowVector& v);
  /// The best `max_results` entries that `allowed(entry)` accepts, by decreasing score, among
  /// those sharing at least one word with `query`.
  std::vector<BowMatch> query(const BowVector& query, int max_results,
                              const std::function<bool(int)>& allowed) const;
  /// Takes `entry` out of every query's results; its number stays taken (entries are not
  /// renumbered) and its vector becomes empty.
  void remove(int entry);
  /// Forgets everything.
  void clear();
  int size() const { return static_cast<int>(vectors_.size()); }
  const BowVector& vector(int entry) const { return vectors_[entry]; }

 private:
  struct Posting {
    int entry;
    double weight;
  };
  std::vector<BowVector> vectors_;
  std::vector<std::vector<Posting>> inverted_;  ///< word -> postings
};

}  // namespace kestrel::slam
