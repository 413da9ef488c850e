#pragma once
// The headline figures of kestrel, as held in one file (results/figures.json): what each
// figure is, on which data, its value in a display unit, the target it is held to, and the
// command, build and date behind it. The README tables are rendered from it (render.h) and
// the data tests take their thresholds from it (test/support/figures.h), so that no figure
// is typed by hand in two places. The format is described in tools/figures/README.md.
//
// Invariants of a FigureFile that load() or parse() returned (anything else throws
// InputError naming the file and the entry):
//  * ids are unique, dotted ("vo.fr1_xyz.ate_rmse") and begin with their component;
//  * the component is one of readme_components(), the unit one of the units below;
//  * a value is a finite number (with a unit) or a text; digits and a limit only with a number;
//  * a limit is min <= max and the figure's own value meets it (a measured value that
//    violates its own limit is an error, not a figure);
//  * every `{id}` a text or note names is a figure of the file whose own value names none;
//  * no string holds a control character (it would break a table row); a date is ISO 8601
//    ("2026-11-27", "2026-11-26T14:05Z", or an interval "A/B"), or empty.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::figures {

/// A display unit: its name in the file, how it is written after a number, and its SI factor
/// (the value in SI units = value * si_factor).
struct Unit {
  const char* name;    ///< as in the file: "cm", "deg/s", "us", "x", "" (a count)
  const char* suffix;  ///< as printed after the number: " cm", " °/s", " µs", "×", ""
  double si_factor;
};

/// The unit named `name`, or nullptr if the loader does not know it.
const Unit* find_unit(const std::string& name);
/// Every known unit, in a fixed order (for messages and the README).
const std::vector<Unit>& units();

/// Inclusive bounds in the figure's display unit; a missing side is unbounded.
struct Limit {
  std::optional<double> min, max;
  bool holds(double value) const;
};

struct Figure {
  std::string id;         ///< "vo.fr1_xyz.ate_rmse"
  std::string component;  ///< the README it belongs to (readme_path)
  std::string table;      ///< the block of that README ("" = its one figures table)
  std::string figure;     ///< the row's label
  std::string data;       ///< which data: sequence, world, frames
  std::optional<double> number;  ///< the value, when it is a number (display unit)
  std::string text;              ///< the value, when it is qualitative (may name {id}s)
  std::string unit;              ///< a units() name; "" for a count or a text
  std::optional<int> digits;     ///< decimals to print; shortest round-trip when empty
  std::string note;              ///< printed after the value (may name {id}s)
  std::string target;            ///< the target as shown
  std::optional<Limit> limit;    ///< what the data tests assert, in the display unit
  std::string command, build, date;

  bool is_number() const { return number.has_value(); }
  /// The value in SI units (number * the unit's factor); throws std::logic_error for a text.
  double value_in_si() const;
  /// The limit in SI units (each side times the unit's factor).
  std::optional<Limit> limit_in_si() const;
};

struct FigureFile {
  std::string source;            ///< the path it was read from (for messages)
  std::vector<Figure> figures;   ///< in file order, which is the tables' row order

  /// The figure with this id, or nullptr.
  const Figure* find(const std::string& id) const;
};

/// Reads and validates the file at `path`; throws InputError "path: ..." if it is missing,
/// is not JSON, or breaks an invariant above (naming the entry's index and id).
FigureFile load(const std::string& path);
/// The same for text already read; `source` names it in messages.
FigureFile parse(const std::string& json_text, const std::string& source);

/// A `{id}` a text names: [begin, end) covers the braces. Braces around anything that is not
/// shaped like an id (`{a,b}`, `{}`) are text, not references.
struct Reference {
  size_t begin, end;
  std::string id;
};
std::vector<Reference> references(const std::string& text);

/// The components that have a README with figures, in a fixed order.
const std::vector<std::string>& readme_components();
/// The README of `component`, relative to the repository root ("vo/README.md", "README.md"
/// for "top"); throws std::out_of_range for an unknown component.
const std::string& readme_path(const std::string& component);

}  // namespace kestrel::figures
