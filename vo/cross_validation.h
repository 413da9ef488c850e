#pragma once
// Leave-one-sequence-out cross-validation of a parameter fitted to recorded data. With the two
// shared TUM clips it is two-fold: the value that scores best on one clip is chosen and scored
// on the other, both ways round. What a fit to the data it is scored on hides (a value that is
// best on one clip only) shows as a held-out score worse than the held-out clip's own best.
//
// Pure bookkeeping over a table of scores (one row per candidate value, one column per
// sequence, lower is better); the runs that fill it are the caller's (kestrel-vo-crossval).
// Invariants: a score that is not finite was not measured and is never chosen; among equal
// scores the value listed first is chosen, so the result does not depend on anything but the
// table.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::vo {

struct CandidateScores {
  std::string value;           ///< as given on the command line
  std::vector<double> scores;  ///< per sequence; not finite = not measured
};

/// Row number of no candidate (a sequence where none was measured).
inline constexpr size_t kNoRow = static_cast<size_t>(-1);

struct Fold {
  size_t fitted_on = 0;        ///< the sequence the value was chosen on
  size_t chosen_row = 0;       ///< the candidate with the lowest score there (its row in the table)
  std::string chosen;          ///< its value
  double fitted_score = 0.0;   ///< its score there
  /// Each other sequence (in sequence order, `fitted_on` left out): the chosen value's score
  /// there, and the best any candidate reaches there (what a fit to that sequence itself would
  /// claim) with its row (kNoRow: none measured).
  std::vector<size_t> held_out;
  std::vector<double> held_out_scores;
  std::vector<double> held_out_best;
  std::vector<size_t> held_out_best_rows;
};

/// One fold per sequence that has a measured candidate (a sequence with none has no fold).
/// Throws std::invalid_argument for an empty table or rows of different lengths.
std::vector<Fold> leave_one_out(const std::vector<CandidateScores>& table);

/// The objectives a value is fitted for, as kestrel-vo-crossval names them.
enum class Objective {
  kAte,          ///< ATE RMSE, m
  kRpeRotation,  ///< RPE rotation over 1 s, deg/s
  kVelocity,     ///< mean frame-to-frame velocity error, m/s (the paper's Table 1 figure)
  kNees,         ///< |ln(mean NEES / 6)|: the covariance's consistency (6 dof), 0 = consistent
};
/// "ate", "rpe-rotation", "velocity", "nees"; nullopt for anything else.
std::optional<Objective> objective_named(const std::string& name);
std::string to_string(Objective objective);

}  // namespace kestrel::vo
