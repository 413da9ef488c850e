// Leave-one-sequence-out cross-validation (vo/cross_validation.h) on hand-made score tables.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "vo/cross_validation.h"

namespace kestrel::vo {
namespace {

const double kNan = std::nan("");

// Two sequences: 2 is best on A and 3 on B; each is scored where the other was fitted.
TEST(CrossValidation, EachSequenceChoosesItsBestAndIsScoredOnTheOther) {
  const std::vector<CandidateScores> table{{"1", {0.5, 4.0}}, {"2", {0.2, 3.0}}, {"3", {0.3, 1.0}}};
  const std::vector<Fold> folds = leave_one_out(table);
  ASSERT_EQ(folds.size(), 2u);
  EXPECT_EQ(folds[0].fitted_on, 0u);
  EXPECT_EQ(folds[0].chosen, "2");
  EXPECT_EQ(folds[0].chosen_row, 1u);
  EXPECT_EQ(folds[0].fitted_score, 0.2);
  EXPECT_EQ(folds[0].held_out, std::vector<size_t>{1});
  EXPECT_EQ(folds[0].held_out_best_rows, std::vector<size_t>{2});
  ASSERT_EQ(folds[0].held_out_scores.size(), 1u);
  EXPECT_EQ(folds[0].held_out_scores[0], 3.0) << "value 2 on B";
  EXPECT_EQ(folds[0].held_out_best[0], 1.0) << "what a fit to B itself claims";
  EXPECT_EQ(folds[1].chosen, "3");
  EXPECT_EQ(folds[1].held_out_scores[0], 0.3);
  EXPECT_EQ(folds[1].held_out_best[0], 0.2);
}

// A value that was not measured somewhere is never chosen there; ties go to the value listed first.
TEST(CrossValidation, UnmeasuredScoresAreNeverChosenAndTiesGoToTheFirst) {
  const std::vector<CandidateScores> table{
      {"a", {kNan, 2.0, 1.0}}, {"b", {0.7, 2.0, kNan}}, {"c", {0.7, 5.0, 1.0}}};
  const std::vector<Fold> folds = leave_one_out(table);
  ASSERT_EQ(folds.size(), 3u);
  EXPECT_EQ(folds[0].chosen, "b") << "a is not measured on the first; b and c tie, b is listed first";
  ASSERT_EQ(folds[0].held_out_scores.size(), 2u);
  EXPECT_EQ(folds[0].held_out_scores[0], 2.0);
  EXPECT_TRUE(std::isnan(folds[0].held_out_scores[1])) << "b was not measured on the third";
  EXPECT_EQ(folds[0].held_out_best[1], 1.0);
  EXPECT_EQ(folds[1].chosen, "a");
  EXPECT_EQ(folds[2].chosen, "a");
}

TEST(CrossValidation, ASequenceWithNothingMeasuredHasNoFold) {
  const std::vector<Fold> folds = leave_one_out({{"a", {1.0, kNan}}, {"b", {2.0, kNan}}});
  ASSERT_EQ(folds.size(), 1u);
  EXPECT_EQ(folds[0].fitted_on, 0u);
  EXPECT_TRUE(std::isnan(folds[0].held_out_best[0]));
  EXPECT_EQ(folds[0].held_out_best_rows[0], kNoRow);
}

TEST(CrossValidation, RefusesATableItCannotRead) {
  EXPECT_THROW(leave_one_out({}), std::invalid_argument);
  EXPECT_THROW(leave_one_out({{"a", {1.0, 2.0}}, {"b", {1.0}}}), std::invalid_argument);
}

TEST(CrossValidation, ObjectivesByName) {
  for (Objective o : {Objective::kAte, Objective::kRpeRotation, Objective::kVelocity, Objective::kNees})
    EXPECT_EQ(objective_named(to_string(o)), o);
  EXPECT_FALSE(objective_named("ATE").has_value());
}

}  // namespace
}  // namespace kestrel::vo
