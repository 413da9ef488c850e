#include "tools/figures/render.h"

#include <charconv>
#include <cmath>
#include <set>
#include <system_error>
#include <vector>

#include "common/error.h"

namespace kestrel::figures {
namespace {

constexpr const char* kBegin = "<!-- figures:begin";
constexpr const char* kEnd = "<!-- figures:end -->";
constexpr const char* kPartsTable = "parts";

std::string cell(const std::string& s) {
  if (s.empty()) return "—";
  std::string out;
  for (const char c : s) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

// `text` with each {id} replaced by the figure's value_text.
std::string expand(const FigureFile& file, const std::string& text) {
  std::string out;
  size_t at = 0;
  for (const Reference& r : references(text)) {
    out += text.substr(at, r.begin - at);
    const Figure* to = file.find(r.id);
    if (!to) throw InputError(file.source + ": {" + r.id + "} names no figure");
    out += value_text(file, *to);
    at = r.end;
  }
  return out + text.substr(at);
}

std::string row(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& c : cells) out += " " + c + " |";
  return out + "\n";
}

// The block name of a begin marker line, or nothing if the line is not one.
std::optional<std::string> begin_name(const std::string& line) {
  const std::string begin = kBegin;
  if (line.compare(0, begin.size(), begin) != 0 || line.size() < begin.size() + 3 ||
      line.compare(line.size() - 3, 3, "-->") != 0)
    return std::nullopt;
  std::string name = line.substr(begin.size(), line.size() - begin.size() - 3);
  if (!name.empty() && name.front() != ' ') return std::nullopt;  // "<!-- figures:beginning"
  const auto first = name.find_first_not_of(' ');
  if (first == std::string::npos) return std::string();
  name = name.substr(first, name.find_last_not_of(' ') - first + 1);
  return name;
}

std::string table_name(const std::string& table) { return table.empty() ? "(unnamed)" : "'" + table + "'"; }

}  // namespace

std::string format_number(double value, std::optional<int> digits) {
  char buffer[64];
  std::to_chars_result r;
  const double magnitude = std::fabs(value);
  if (digits) {
    r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed, *digits);
  } else if (value != 0.0 && (magnitude < 1e-4 || magnitude >= 1e16)) {
    r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::scientific);
  } else {
    r = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  }
  if (r.ec != std::errc()) return "?";  // 64 characters hold any double in these formats
  return std::string(buffer, r.ptr);
}

std::string value_text(const FigureFile& file, const Figure& figure) {
  if (!figure.number) return expand(file, figure.text);
  return format_number(*figure.number, figure.digits) + find_unit(figure.unit)->suffix;
}

std::string value_cell(const FigureFile& file, const Figure& figure) {
  std::string out = value_text(file, figure);
  if (!figure.note.empty()) out += " " + expand(file, figure.note);
  return out;
}

std::string render_table(const FigureFile& file, const std::string& component, const std::string& table) {
  const bool parts = table == kPartsTable;
  std::string out = parts ? row({"part", "README", "headline"}) + "|---|---|---|\n"
                          : row({"figure", "data", "value", "target", "command", "build", "date"}) +
                                "|---|---|---|---|---|---|---|\n";
  size_t rows = 0;
  for (const Figure& f : file.figures) {
    if (f.component != component || f.table != table) continue;
    const std::string value = cell(value_cell(file, f));
    out += parts ? row({cell(f.figure), cell(f.data), value})
                 : row({cell(f.figure), cell(f.data), value, cell(f.target), cell(f.command), cell(f.build),
                        cell(f.date)});
    ++rows;
  }
  if (rows == 0)
    throw InputError(file.source + ": no figure of component '" + component + "' is in table " + table_name(table));
  return out;
}

std::string render_readme(const FigureFile& file, const std::string& component, const std::string& readme,
                          const std::string& readme_name) {
  std::vector<std::string> lines;
  for (size_t at = 0; at < readme.size();) {
    const size_t nl = readme.find('\n', at);
    const size_t end = nl == std::string::npos ? readme.size() : nl;
    lines.push_back(readme.substr(at, end - at));
    at = end + 1;
  }
  const bool final_newline = !readme.empty() && readme.back() == '\n';

  std::string out;
  std::set<std::string> rendered;
  std::optional<std::string> open;  // the block being skipped
  size_t open_line = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    const std::string where = readme_name + ":" + std::to_string(i + 1) + ": ";
    if (const auto name = begin_name(line)) {
      if (open) throw InputError(where + "a figures:begin inside the block that begins at line " + std::to_string(open_line));
      if (!rendered.insert(*name).second) throw InputError(where + "a second block for table " + table_name(*name));
      open = *name;
      open_line = i + 1;
      out += line + "\n" + render_table(file, component, *name);
      continue;
    }
    if (line == kEnd) {
      if (!open) throw InputError(where + "a figures:end without a figures:begin");
      open.reset();
    } else if (open) {
      continue;  // the old table
    }
    out += line;
    if (i + 1 < lines.size() || final_newline) out += "\n";
  }
  if (open) throw InputError(readme_name + ":" + std::to_string(open_line) + ": a figures:begin without a figures:end");
  for (const Figure& f : file.figures) {
    if (f.component == component && !rendered.count(f.table))
      throw InputError(readme_name + ": no figures block for table " + table_name(f.table) + " (figure " + f.id +
                       " of " + file.source + ")");
  }
  return out;
}

bool has_figures_block(const std::string& readme) {
  for (size_t at = 0; at < readme.size();) {
    const size_t nl = readme.find('\n', at);
    const size_t end = nl == std::string::npos ? readme.size() : nl;
    if (begin_name(readme.substr(at, end - at))) return true;
    at = end + 1;
  }
  return false;
}

}  // namespace kestrel::figures
