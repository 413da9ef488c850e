#include "vo/cross_validation.h"

#include <cmath>
#include <stdexcept>

namespace kestrel::vo {

std::vector<Fold> leave_one_out(const std::vector<CandidateScores>& table) {
  if (table.empty()) throw std::invalid_argument("cross-validation: no candidate values");
  const size_t sequences = table.front().scores.size();
  for (const CandidateScores& row : table) {
    if (row.scores.size() != sequences)
      throw std::invalid_argument("cross-validation: value " + row.value + " has " + std::to_string(row.scores.size()) +
                                  " scores where the first has " + std::to_string(sequences));
  }
  // The lowest measured score of sequence s and its row (the first of equals); nullopt when none.
  const auto best_of = [&](size_t s) -> std::optional<size_t> {
    std::optional<size_t> best;
    for (size_t r = 0; r < table.size(); ++r) {
      const double v = table[r].scores[s];
      if (std::isfinite(v) && (!best || v < table[*best].scores[s])) best = r;
    }
    return best;
  };
  std::vector<Fold> folds;
  for (size_t fit = 0; fit < sequences; ++fit) {
    const std::optional<size_t> chosen = best_of(fit);
    if (!chosen) continue;
    Fold f;
    f.fitted_on = fit;
    f.chosen_row = *chosen;
    f.chosen = table[*chosen].value;
    f.fitted_score = table[*chosen].scores[fit];
    for (size_t s = 0; s < sequences; ++s) {
      if (s == fit) continue;
      f.held_out.push_back(s);
      f.held_out_scores.push_back(table[*chosen].scores[s]);
      const std::optional<size_t> best = best_of(s);
      f.held_out_best.push_back(best ? table[*best].scores[s] : std::nan(""));
      f.held_out_best_rows.push_back(best.value_or(kNoRow));
    }
    folds.push_back(std::move(f));
  }
  return folds;
}

std::optional<Objective> objective_named(const std::string& name) {
  for (Objective o : {Objective::kAte, Objective::kRpeRotation, Objective::kVelocity, Objective::kNees})
    if (name == to_string(o)) return o;
  return std::nullopt;
}

std::string to_string(Objective objective) {
  switch (objective) {
    case Objective::kAte: return "ate";
    case Objective::kRpeRotation: return "rpe-rotation";
    case Objective::kVelocity: return "velocity";
    case Objective::kNees: return "nees";
  }
  return "?";
}

}  // namespace kestrel::vo
