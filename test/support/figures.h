#pragma once
// The figures of results/figures.json as the data tests use them: a test takes its thresholds
// from the file the READMEs are rendered from, never from numbers of its own, so a figure and
// the bound a test holds it to cannot drift apart (CONTRIBUTING.md, "Figures").
//
// Invariants: values and limits are in SI units (metres, seconds, radians, fractions for %;
// a count or a ratio as it is), converted by the unit's factor; the file is read and validated
// once per test binary, and an id that is absent or names a text is an error (the test that
// asked fails with the id in its message), never a silent default.

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace kestrel::test {

/// One numeric figure in SI units.
struct Figure {
  std::string id;
  double value = 0.0;  ///< the measured figure
  double min = -std::numeric_limits<double>::infinity();  ///< the limit's lower side, or -inf
  double max = std::numeric_limits<double>::infinity();   ///< the limit's upper side, or +inf
  bool has_limit = false;
  std::string shown;  ///< as the README shows it ("0.94 cm"), for messages
};

/// The figure `id` of KESTREL_SOURCE_DIR/results/figures.json. Throws std::runtime_error
/// (which fails the calling test) if the file does not validate, or the id is absent or not a
/// number.
const Figure& figure(const std::string& id);

/// A data test fails on a regression of more than 10 % over the recorded figure.
inline constexpr double kRegressionFactor = 1.1;

/// Passes if `measured_si` meets the figure's limit; fails if it does not, or if the figure
/// has no limit (a test that asks for one relies on it).
::testing::AssertionResult within_limit(double measured_si, const Figure& f);

/// Passes if `measured_si` <= factor x the figure's value (for a figure where lower is better).
::testing::AssertionResult no_worse_than(double measured_si, const Figure& f,
                                         double factor = kRegressionFactor);

}  // namespace kestrel::test
