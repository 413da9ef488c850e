#include "tools/figures/figures.h"

#include <nlohmann/json.hpp>

#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/error.h"
#include "common/text.h"
#include "common/numbers.h"

namespace kestrel::figures {
namespace {

using nlohmann::json;

// The units a figure may be given in. SI factors: lengths to m, times to s, angles to rad,
// percentages to a fraction, sizes to bytes; a ratio ("x") and a count ("") are their own.
const std::vector<Unit> kUnits = {
    {"m", " m", 1.0},          {"cm", " cm", 1e-2},       {"mm", " mm", 1e-3},
    {"um", " µm", 1e-6},       {"s", " s", 1.0},          {"min", " min", 60.0},
    {"ms", " ms", 1e-3},       {"us", " µs", 1e-6},       {"Hz", " Hz", 1.0},
    {"m/s", " m/s", 1.0},      {"deg", "°", kPi / 180.0}, {"deg/s", " °/s", kPi / 180.0},
    {"rad", " rad", 1.0},      {"rad/s", " rad/s", 1.0},  {"%", " %", 1e-2},
    {"kB", " kB", 1e3},        {"MB", " MB", 1e6},        {"GB", " GB", 1e9},
    {"x", "×", 1.0},           {"", "", 1.0},
};

const std::vector<std::pair<std::string, std::string>> kReadmes = {
    {"top", "README.md"},
    {"sim", "drivers/sim/README.md"},
    {"tum", "drivers/tum/README.md"},
    {"kinect", "drivers/kinect/README.md"},
    {"vo", "vo/README.md"},
    {"estimator", "estimator/README.md"},
    {"slam", "slam/README.md"},
    {"mapper", "mapper/README.md"},
    {"planner", "planner/README.md"},
    {"control", "control/README.md"},
    {"eval", "tools/eval/README.md"},
    {"replay", "tools/replay/README.md"},
    {"launch", "tools/launch/README.md"},
    {"fuzz", "fuzz/README.md"},
    {"station", "station/README.md"},
};

const std::set<std::string> kKeys = {"id",   "component", "table", "figure", "data",  "value",   "unit",
                                     "digits", "note",    "target", "limit", "command", "build", "date"};

// A string as it may appear in a one-line message: control bytes escaped, so that a damaged
// file cannot put raw bytes on the operator's terminal.
std::string shown(const std::string& s) { return "'" + escape_bytes(s) + "'"; }

bool id_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

// Dotted, at least two non-empty segments of [a-z0-9_-].
bool is_id(const std::string& s) {
  if (s.empty() || s.front() == '.' || s.back() == '.' || s.find("..") != std::string::npos) return false;
  if (s.find('.') == std::string::npos) return false;
  for (const char c : s)
    if (c != '.' && !id_char(c)) return false;
  return true;
}

bool digits_at(const std::string& s, size_t at, size_t n, int lo, int hi) {
  if (at + n > s.size()) return false;
  int v = 0;
  for (size_t i = at; i < at + n; ++i) {
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
    v = v * 10 + (s[i] - '0');
  }
  return v >= lo && v <= hi;
}

// YYYY-MM-DD, optionally THH:MMZ.
bool is_instant(const std::string& s) {
  if (s.size() != 10 && s.size() != 17) return false;
  if (!digits_at(s, 0, 4, 1970, 9999) || s[4] != '-' || !digits_at(s, 5, 2, 1, 12) || s[7] != '-' ||
      !digits_at(s, 8, 2, 1, 31))
    return false;
  if (s.size() == 10) return true;
  return s[10] == 'T' && digits_at(s, 11, 2, 0, 23) && s[13] == ':' && digits_at(s, 14, 2, 0, 59) && s[16] == 'Z';
}

bool is_date(const std::string& s) {
  if (s.empty()) return true;
  const auto slash = s.find('/');
  if (slash == std::string::npos) return is_instant(s);
  return is_instant(s.substr(0, slash)) && is_instant(s.substr(slash + 1));
}

class EntryReader {
 public:
  EntryReader(const std::string& source, size_t index, const json& j) : source_(source), index_(index), j_(j) {}

  [[noreturn]] void fail(const std::string& what) const {
    std::string where = source_ + ": figures[" + std::to_string(index_) + "]";
    if (!id_.empty()) where += " (" + shown(id_) + ")";
    throw InputError(where + ": " + what);
  }

  std::string string(const char* key, bool required) const {
    if (!j_.contains(key)) {
      if (required) fail(std::string("no \"") + key + "\"");
      return {};
    }
    const json& v = j_.at(key);
    if (!v.is_string()) fail(std::string("\"") + key + "\" is not a string");
    const std::string s = v.get<std::string>();
    for (const unsigned char c : s)
      if (c < 0x20 || c == 0x7f) fail(std::string("\"") + key + "\" holds a control character: " + shown(s));
    return s;
  }

  double number(const json& v, const std::string& what) const {
    if (!v.is_number()) fail(what + " is not a number");
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(what + " is not finite");
    return d;
  }

  Figure read() {
    if (!j_.is_object()) fail("not an object");
    if (j_.contains("id") && j_.at("id").is_string()) id_ = j_.at("id").get<std::string>();
    for (const auto& [key, value] : j_.items()) {
      (void)value;
      if (!kKeys.count(key)) fail("unknown key " + shown(key));
    }
    Figure f;
    f.id = string("id", true);
    if (!is_id(f.id)) fail("the id is not dotted lower-case words ([a-z0-9_-] separated by '.')");
    f.component = string("component", true);
    bool known = false;
    for (const auto& [component, path] : kReadmes) known = known || component == f.component;
    if (!known) fail("unknown component " + shown(f.component));
    if (f.id.compare(0, f.component.size() + 1, f.component + ".") != 0)
      fail("the id does not begin with its component, \"" + f.component + ".\"");
    f.table = string("table", false);
    f.figure = string("figure", true);
    if (f.figure.empty()) fail("\"figure\" is empty");
    f.data = string("data", true);
    f.note = string("note", false);
    f.target = string("target", true);
    f.command = string("command", true);
    f.build = string("build", true);
    f.date = string("date", true);
    if (!is_date(f.date)) fail("the date " + shown(f.date) + " is not ISO 8601 (YYYY-MM-DD[THH:MMZ][/...]) or empty");

    if (!j_.contains("value")) fail("no \"value\"");
    const json& value = j_.at("value");
    if (value.is_string()) {
      f.text = string("value", true);
      if (f.text.empty()) fail("the value is an empty text");
      if (!string("unit", false).empty()) fail("a text value has no unit");
      if (j_.contains("digits")) fail("\"digits\" is for a number");
      if (j_.contains("limit")) fail("a limit needs a number to hold");
      return f;
    }
    f.number = number(value, "the value");
    if (!j_.contains("unit")) fail("a number needs a \"unit\" (\"\" for a count)");
    f.unit = string("unit", true);
    if (!find_unit(f.unit)) {
      std::string known_units;
      for (const Unit& u : kUnits) known_units += std::string(known_units.empty() ? "" : ", ") + "\"" + u.name + "\"";
      fail("unknown unit " + shown(f.unit) + " (known: " + known_units + ")");
    }
    if (j_.contains("digits")) {
      const json& d = j_.at("digits");
      if (!d.is_number_integer() || d.get<long long>() < 0 || d.get<long long>() > 12)
        fail("\"digits\" is not a whole number from 0 to 12");
      f.digits = d.get<int>();
    }
    if (j_.contains("limit")) f.limit = limit(j_.at("limit"), *f.number);
    return f;
  }

 private:
  Limit limit(const json& j, double value) const {
    if (!j.is_object() || j.size() != 1)
      fail("the limit is not one of {\"max\": n}, {\"min\": n}, {\"range\": [a, b]}");
    Limit l;
    if (j.contains("max")) {
      l.max = number(j.at("max"), "the limit's max");
    } else if (j.contains("min")) {
      l.min = number(j.at("min"), "the limit's min");
    } else if (j.contains("range")) {
      const json& r = j.at("range");
      if (!r.is_array() || r.size() != 2) fail("the limit's range is not [a, b]");
      l.min = number(r[0], "the range's first bound");
      l.max = number(r[1], "the range's second bound");
      if (*l.min > *l.max) fail("the limit's range [a, b] has a > b");
    } else {
      fail("the limit is not one of {\"max\": n}, {\"min\": n}, {\"range\": [a, b]}");
    }
    if (!l.holds(value)) {
      std::ostringstream what;
      what.precision(17);
      what << "the value " << value << " violates its own limit";
      if (l.min) what << " (min " << *l.min << ")";
      if (l.max) what << " (max " << *l.max << ")";
      fail(what.str());
    }
    return l;
  }

  const std::string& source_;
  size_t index_;
  const json& j_;
  std::string id_;
};

}  // namespace

const Unit* find_unit(const std::string& name) {
  for (const Unit& u : kUnits)
    if (name == u.name) return &u;
  return nullptr;
}

const std::vector<Unit>& units() { return kUnits; }

bool Limit::holds(double value) const { return (!min || value >= *min) && (!max || value <= *max); }

double Figure::value_in_si() const {
  if (!number) throw std::logic_error("figure " + id + " is a text, not a number");
  return *number * find_unit(unit)->si_factor;
}

std::optional<Limit> Figure::limit_in_si() const {
  if (!limit) return std::nullopt;
  const double k = find_unit(unit)->si_factor;
  Limit l;
  if (limit->min) l.min = *limit->min * k;
  if (limit->max) l.max = *limit->max * k;
  return l;
}

const Figure* FigureFile::find(const std::string& id) const {
  for (const Figure& f : figures)
    if (f.id == id) return &f;
  return nullptr;
}

std::vector<Reference> references(const std::string& text) {
  std::vector<Reference> out;
  for (size_t open = text.find('{'); open != std::string::npos; open = text.find('{', open + 1)) {
    const size_t close = text.find('}', open + 1);
    if (close == std::string::npos) break;
    const std::string inner = text.substr(open + 1, close - open - 1);
    if (is_id(inner)) out.push_back({open, close + 1, inner});
  }
  return out;
}

FigureFile parse(const std::string& json_text, const std::string& source) {
  json root;
  try {
    root = json::parse(json_text);
  } catch (const json::exception& e) {  // parse_error, and out_of_range for a number like 1e999
    throw InputError(source + ": not JSON: " + e.what());
  }
  if (!root.is_object() || !root.contains("figures") || !root.at("figures").is_array())
    throw InputError(source + ": not an object {\"figures\": [...]}");
  for (const auto& [key, value] : root.items()) {
    (void)value;
    if (key != "figures" && key != "about") throw InputError(source + ": unknown key " + shown(key));
  }
  FigureFile file;
  file.source = source;
  std::map<std::string, size_t> index_of;
  const json& entries = root.at("figures");
  for (size_t i = 0; i < entries.size(); ++i) {
    EntryReader reader(source, i, entries[i]);
    Figure f = reader.read();
    if (const auto [it, inserted] = index_of.emplace(f.id, i); !inserted)
      reader.fail("the id is also figures[" + std::to_string(it->second) + "]'s");
    file.figures.push_back(std::move(f));
  }
  // References, once every id is known: to a figure of the file whose own value names none,
  // so that an expansion is one step and cannot loop.
  for (size_t i = 0; i < file.figures.size(); ++i) {
    const Figure& f = file.figures[i];
    for (const std::string* text : {&f.text, &f.note}) {
      for (const Reference& r : references(*text)) {
        const Figure* to = file.find(r.id);
        const std::string where = source + ": figures[" + std::to_string(i) + "] (" + shown(f.id) + ")";
        if (!to) throw InputError(where + ": {" + r.id + "} names no figure");
        if (!references(to->text).empty())
          throw InputError(where + ": {" + r.id + "} names a figure whose value names others");
      }
    }
  }
  return file;
}

FigureFile load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot be read");
  std::ostringstream all;
  all << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read failed");
  return parse(all.str(), path);
}

const std::vector<std::string>& readme_components() {
  static const std::vector<std::string> components = [] {
    std::vector<std::string> c;
    for (const auto& [component, path] : kReadmes) c.push_back(component);
    return c;
  }();
  return components;
}

const std::string& readme_path(const std::string& component) {
  for (const auto& [c, path] : kReadmes)
    if (c == component) return path;
  throw std::out_of_range("no README for component '" + component + "'");
}

}  // namespace kestrel::figures
