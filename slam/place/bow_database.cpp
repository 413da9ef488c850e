#include "slam/place/bow_database.h"

#include <algorithm>
#include <unordered_map>

namespace kestrel::slam {

int BowDatabase::add(const BowVector& v) {
  const int entry = static_cast<int>(vectors_.size());
  vectors_.push_back(v);
  for (const auto& [word, weight] : v) {
    if (word >= static_cast<int>(inverted_.size())) inverted_.resize(static_cast<size_t>(word) + 1);
    inverted_[word].push_back(Posting{entry, weight});
  }
  return entry;
}

std::vector<BowMatch> BowDatabase::query(const BowVector& query, int max_results,
                                         const std::function<bool(int)>& allowed) const {
  // Accumulate sum over shared words of min(q_w, d_w): the L1 score of normalised vectors.
  std::unordered_map<int, double> scores;
  for (const auto& [word, q] : query) {
    if (word >= static_cast<int>(inverted_.size())) continue;
    for (const Posting& p : inverted_[word]) scores[p.entry] += std::min(q, p.weight);
  }
  std::vector<BowMatch> matches;
  matches.reserve(scores.size());
  for (const auto& [entry, score] : scores) {
    if (!allowed || allowed(entry)) matches.push_back(BowMatch{entry, score});
  }
  const size_t keep = std::min(matches.size(), static_cast<size_t>(std::max(max_results, 0)));
  std::partial_sort(matches.begin(), matches.begin() + static_cast<std::ptrdiff_t>(keep), matches.end(),
                    [](const BowMatch& a, const BowMatch& b) {
                      return a.score != b.score ? a.score > b.score : a.entry < b.entry;
                    });
  matches.resize(keep);
  return matches;
}

void BowDatabase::remove(int entry) {
  if (entry < 0 || entry >= size()) return;
  for (const auto& [word, weight] : vectors_[static_cast<size_t>(entry)]) {
    auto& postings = inverted_[static_cast<size_t>(word)];
    postings.erase(std::remove_if(postings.begin(), postings.end(), [entry](const Posting& p) { return p.entry == entry; }),
                   postings.end());
  }
  vectors_[static_cast<size_t>(entry)] = BowVector{};
}

void BowDatabase::clear() {
  vectors_.clear();
  inverted_.clear();
}

}  // namespace kestrel::slam
