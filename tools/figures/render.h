#pragma once
// The README tables rendered from a FigureFile (figures.h), and a README's figures blocks
// replaced by their rendering. A block is the lines between `<!-- figures:begin -->` (or
// `<!-- figures:begin NAME -->`, for a README with more than one table) and
// `<!-- figures:end -->`; it holds the figures of the README's component whose `table` is
// NAME ("" for the unnamed block), one row each, in file order.
//
// Invariants: rendering is a pure function of the file (no dates, no locale), so that a
// README regenerated twice is byte-identical and a test can compare it; a cell never holds
// a raw '|' or line break (pipes are escaped as `\|`, line breaks cannot load); everything
// outside the blocks is kept byte for byte.
//
// Layouts: a block named "parts" (the top README's "Where each part stands") has the columns
// part | README | headline (the figure, its data, its value); every other block has
// figure | data | value | target | command | build | date, an empty cell shown as "—".

#include <optional>
#include <string>

#include "tools/figures/figures.h"

namespace kestrel::figures {

/// `value` with `digits` decimals, or the shortest text that reads back as the same double
/// (fixed notation from 1e-4 to 1e16, scientific outside it).
std::string format_number(double value, std::optional<int> digits);

/// What `{id}` expands to: a number with its unit ("0.94 cm", "0.038×", "74"), or the text
/// with its own references expanded.
std::string value_text(const FigureFile& file, const Figure& figure);
/// The value column: value_text, then the note (references expanded) after one space.
std::string value_cell(const FigureFile& file, const Figure& figure);

/// The Markdown table (header, rule, rows; each line ending in '\n') of `component`'s block
/// `table`; throws InputError if no figure belongs to it.
std::string render_table(const FigureFile& file, const std::string& component, const std::string& table);

/// `readme` (the text of `component`'s README, named `readme_name` in messages) with every
/// figures block replaced by its table. Throws InputError "<readme_name>:<line>: ..." for a
/// begin without an end or inside another block, an end without a begin, a table given two
/// blocks, or a table of the component's figures that has no block.
std::string render_readme(const FigureFile& file, const std::string& component, const std::string& readme,
                          const std::string& readme_name);

/// Whether `readme` has at least one figures block (a README without one needs no figures).
bool has_figures_block(const std::string& readme);

}  // namespace kestrel::figures
